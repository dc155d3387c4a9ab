// `boxd record --config FILE --out DIR`: drives the station of a config file once (turntable
// poses, raw depth frames) and writes the session (SPEC section 3).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "daemon/cli.h"
#include "drivers/capture_loop.h"
#include "drivers/driver_registry.h"
#include "drivers/station_config.h"
#include "pipeline/session_io.h"

namespace boxd::cli {

namespace {

namespace fs = std::filesystem;

struct RecordOptions {
    fs::path config;
    fs::path out;
    bool force = false;
};

// Set by SIGINT/SIGTERM; the capture loop stops the table and returns.
std::atomic<bool> g_cancel{false};

void OnRecordStopSignal(int) { g_cancel.store(true); }

bool IsInputError(const Error& e) { return CategoryOf(e.code) == ErrorCategory::kBadInput; }

int RunRecord(const RecordOptions& options) {
    auto config = LoadStationConfig(options.config);
    if (!config) return FailBadInput(config.error().message);
    std::error_code ec;
    if (fs::exists(options.out, ec) && !options.force &&
        !(fs::is_directory(options.out, ec) && fs::is_empty(options.out, ec))) {
        return FailBadInput("--out " + options.out.string() +
                            ": exists and is not an empty folder (use --force to write into it)");
    }

    auto devices = OpenStation(*config);
    if (!devices) {
        if (IsInputError(devices.error())) return FailBadInput(devices.error().message);
        std::fprintf(stderr, "boxd: error: %s: %s\n", ErrorCodeName(devices.error().code),
                     devices.error().message.c_str());
        return kExitInternal;
    }
    if (!devices->calibrated) {
        spdlog::warn(
            "the config has no calibration section: the session carries the default "
            "calibration; run boxd calibrate before measuring");
    }

    g_cancel.store(false);
    std::signal(SIGINT, OnRecordStopSignal);
    std::signal(SIGTERM, OnRecordStopSignal);
    CaptureCallbacks callbacks;
    callbacks.cancel = &g_cancel;
    callbacks.on_progress = [](int pose, int poses) {
        if (pose < poses) spdlog::info("capture: pose {} of {}", pose + 1, poses);
    };
    auto session = CaptureSession(*devices->turntable, *devices->camera, devices->capture,
                                  devices->station, callbacks);
    devices->camera->Close();
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    if (!session) {
        std::fprintf(stderr, "boxd: error: %s: %s\n", ErrorCodeName(session.error().code),
                     session.error().message.c_str());
        return kExitInternal;
    }
    if (auto st = WriteSession(*session, options.out); !st) {
        std::fprintf(stderr, "boxd: error: %s\n", st.error().message.c_str());
        return kExitInternal;
    }
    std::size_t frames = 0;
    for (const auto& pose : session->poses) frames += pose.frames.size();
    const nlohmann::json summary = {{"session", options.out.string()},
                                    {"source", session->source},
                                    {"poses", session->poses.size()},
                                    {"frames", frames}};
    std::printf("%s\n", summary.dump().c_str());
    return kExitOk;
}

}  // namespace

void AddRecord(CLI::App& app, Runner& run) {
    auto options = std::make_shared<RecordOptions>();
    CLI::App* sub = app.add_subcommand("record", "Drive the station once and write a session");
    sub->add_option("--config", options->config, "Station config (YAML)")->required();
    sub->add_option("--out", options->out, "Session folder to write")->required();
    sub->add_flag("--force", options->force, "Write into a folder that is not empty");
    sub->callback([&run, options] { run = [options] { return RunRecord(*options); }; });
}

}  // namespace boxd::cli
