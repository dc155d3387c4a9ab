// boxd measure: measures a recorded session offline and prints the SPEC section 5 JSON.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>

#include "daemon/cli/cli.h"
#include "daemon/cli/cli_progress.h"
#include "daemon/service/billing.h"
#include "daemon/service/daemon_config.h"
#include "drivers/station_config.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/ply_writer.h"
#include "pipeline/io/session_io.h"
#include "pipeline/measure_pipeline.h"

namespace boxd::cli {

namespace {

struct MeasureOptions {
    std::string session;
    std::string method = "footprint";
    std::string cloud;
    std::string calibration;
    std::string config;
    std::optional<std::string> parcel_id;
};

int RunMeasure(const MeasureOptions& opt) {
    if (opt.parcel_id) {
        if (Status s = CheckParcelId(*opt.parcel_id); !s) {
            return Fail(Error{ErrorCode::kInvalidInput, "--parcel-id " + s.error().message});
        }
    }
    KeepFreedBuffers();
    // The frames are read pose by pose as the poses are prepared, not all held at once.
    auto session = LoadSessionHeader(opt.session);
    if (!session) return Fail(session.error());
    if (!opt.calibration.empty()) {
        // A station recalibrated after the capture: its calibration replaces the session's.
        auto calibration = LoadCalibrationFile(opt.calibration);
        if (!calibration) {
            return Fail(
                Error{ErrorCode::kInvalidInput, "--calibration: " + calibration.error().message});
        }
        session->calibration = *calibration;
    }
    MeasureConfig config;
    std::optional<BillingConfig> billing;
    if (!opt.config.empty()) {
        // The station's `measurement:` and `billing:` settings, as its daemon uses them.
        auto loaded = LoadMeasurementConfig(opt.config);
        if (!loaded) {
            return Fail(Error{ErrorCode::kInvalidInput, "--config: " + loaded.error().message});
        }
        config = *loaded;
        auto bills = LoadBillingConfig(opt.config);
        if (!bills)
            return Fail(Error{ErrorCode::kInvalidInput, "--config: " + bills.error().message});
        billing = *bills;
    }
    const BoxMethod method = opt.method == "pca" ? BoxMethod::kPca : BoxMethod::kFootprint;
    // The command line is an edge of the pipeline: it owns the id, the timestamps and the clock.
    const MonotonicMs clock = SteadyClockMs();
    const std::string started_at = UtcTimestampNow();
    const double start_ms = clock();
    Progress progress("measure");
    const int poses = static_cast<int>(session->poses.size());
    const PoseFrameSource frames = [&](std::size_t pose) {
        progress.Step("prepared", static_cast<int>(pose), poses);
        return LoadPoseFrames(opt.session, *session, pose);
    };
    auto out = MeasureFromSource(*session, frames, config, method, clock);
    progress.Step("prepared", poses, poses);
    progress.Finish();
    if (!out) return Fail(out.error());
    MeasurementResult& result = out->result;
    result.id = "offline";
    result.parcel_id = opt.parcel_id;
    result.started_at = started_at;
    result.finished_at = UtcTimestampNow();
    result.timing_ms["capture"] = 0.0;
    result.timing_ms["processing"] = clock() - start_ms;
    if (!opt.cloud.empty()) {
        // The path is the caller's: one that cannot be written is bad input (exit 2).
        if (Status s = WritePly(opt.cloud, out->cloud); !s) {
            return Fail(Error{ErrorCode::kInvalidInput, "--cloud: " + s.error().message});
        }
    }
    AddBilling(result, billing, std::nullopt);
    const std::string text = JsonText(ToJson(out->result), 2);
    std::fprintf(stdout, "%s\n", text.c_str());
    std::fflush(stdout);
    switch (out->result.status) {
        case MeasurementStatus::kOk:
            return kExitOk;
        case MeasurementStatus::kNoDim:
            return kExitNoDim;
        case MeasurementStatus::kFailed:
            break;
    }
    return kExitInternal;
}

}  // namespace

void AddMeasure(CLI::App& app, Runner& run) {
    auto opt = std::make_shared<MeasureOptions>();
    CLI::App* sub = app.add_subcommand("measure", "Measure a recorded session offline");
    sub->add_option("--session", opt->session, "session folder (boxd.session/1)")->required();
    sub->add_option("--method", opt->method, "dimension estimator")
        ->check(CLI::IsMember({"footprint", "pca"}))
        ->capture_default_str();
    sub->add_option("--cloud", opt->cloud, "write the fused cloud (table frame) as a PLY file");
    sub->add_option("--calibration", opt->calibration,
                    "a calibration file (what `boxd calibrate --out` writes): replaces the "
                    "session's calibration block");
    sub->add_option("--config", opt->config,
                    "a station config file: its `measurement:` section (max_uncertainty_m, "
                    "calibration_center_sigma_m) replaces the defaults, and its `billing:` "
                    "section adds the result's billing block");
    sub->add_option("--parcel-id", opt->parcel_id,
                    "the parcel's id (e.g. its scanned barcode: 1 to 64 printable ASCII "
                    "characters), kept in the result as parcel_id");
    sub->callback([&run, opt] { run = [opt] { return RunMeasure(*opt); }; });
}

}  // namespace boxd::cli
