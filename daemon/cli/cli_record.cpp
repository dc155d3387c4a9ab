// `boxd record --config FILE --out DIR`: drives the station of a config file once (turntable
// poses, raw depth frames) and writes the session (SPEC section 3).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "daemon/cli/cli.h"
#include "daemon/cli/cli_progress.h"
#include "drivers/capture_loop.h"
#include "drivers/driver_registry.h"
#include "drivers/station_config.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/session_io.h"

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

int RunRecord(const RecordOptions& options) {
    auto config = LoadStationConfig(options.config);
    if (!config) return Fail(config.error());
    if (auto st = CheckOutFolder(options.out, options.force); !st) return Fail(st.error());

    auto devices = OpenStation(*config);
    if (!devices) return Fail(devices.error());
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
    Progress progress("record", std::chrono::milliseconds(0));  // a table turning
    callbacks.on_progress = [&progress](int pose, int poses) {
        progress.Step("captured", pose, poses);  // `pose` poses are captured
    };
    // A recording keeps the fixed schedule: from 0, forwards.
    CaptureConfig capture = devices->capture;
    capture.sweep = "from_zero";
    capture.order = "sequential";  // a recording keeps the fixed schedule
    auto session =
        CaptureSession(*devices->turntable, *devices->camera, capture, devices->station, callbacks);
    progress.Finish();
    devices->camera->Close();
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    if (!session) return Fail(session.error());
    if (auto st = WriteSession(*session, options.out); !st) return Fail(st.error());
    std::size_t frames = 0;
    for (const auto& pose : session->poses) frames += pose.frames.size();
    const nlohmann::json summary = {{"session", options.out.string()},
                                    {"source", session->source},
                                    {"poses", session->poses.size()},
                                    {"frames", frames}};
    std::printf("%s\n", JsonText(summary).c_str());
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
