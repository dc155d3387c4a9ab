// boxd calibrate: estimates the station calibration from a session of a reference box and prints
// the calibration JSON (SPEC section 3 block plus quality figures); --out writes the calibration
// file (YAML, a `calibration:` section for the station config).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "calibration/station_calibrator.h"
#include "daemon/cli/cli.h"
#include "daemon/cli/cli_progress.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/session_io.h"

namespace boxd::cli {

namespace {

struct CalibrateOptions {
    std::string session;
    std::vector<double> reference;
    std::string out;
    bool estimate_depth_scale = false;
    bool hold_focal_scale = false;
};

int RunCalibrate(const CalibrateOptions& opt) {
    auto session = LoadSession(opt.session);
    if (!session) return Fail(session.error());
    const BoxDimensions reference{opt.reference[0], opt.reference[1], opt.reference[2]};
    CalibrationConfig config;
    config.estimate_depth_scale = opt.estimate_depth_scale;
    config.estimate_focal_scale = !opt.hold_focal_scale;
    // A refusal (too few poses, table not visible, wrong reference, box moved, no convergence)
    // is a problem of the input session: its category makes it exit 2 with the code in the line.
    Progress progress("calibrate", std::chrono::milliseconds(0));  // always seconds
    auto report = CalibrateStation(
        *session, reference, config,
        [&progress](const char* step, int done, int total) { progress.Step(step, done, total); });
    progress.Finish();
    if (!report) return Fail(report.error());
    if (!opt.out.empty()) {
        std::ofstream file(opt.out);
        file << CalibrationYaml(*report);
        file.close();
        // The path is the caller's: one that cannot be written is bad input (exit 2).
        if (!file) {
            return Fail(Error{ErrorCode::kInvalidInput,
                              "--out: cannot write the calibration file " + opt.out});
        }
    }
    const std::string text = JsonText(ToJson(*report), 2);
    std::fprintf(stdout, "%s\n", text.c_str());
    std::fflush(stdout);
    return kExitOk;
}

}  // namespace

void AddCalibrate(CLI::App& app, Runner& run) {
    auto opt = std::make_shared<CalibrateOptions>();
    CLI::App* sub = app.add_subcommand(
        "calibrate",
        "Estimate the station calibration (turntable centre and axis, depth offset) from a "
        "session of a reference box of known size. Exit 2 with a one-line error when the "
        "session cannot calibrate (TOO_FEW_POSES, TABLE_NOT_VISIBLE, NO_REFERENCE, "
        "WRONG_REFERENCE, BOX_MOVED, NOT_CONVERGED)");
    sub->add_option("--session", opt->session, "session folder (boxd.session/1)")->required();
    sub->add_option("--reference", opt->reference, "reference box size L W H in metres")
        ->required()
        ->expected(3)
        ->check(CLI::PositiveNumber);
    sub->add_option("--out", opt->out,
                    "write the calibration file (YAML: a `calibration:` section for the station "
                    "config)");
    sub->add_flag("--hold-focal-scale", opt->hold_focal_scale,
                  "keep the session's focal_scale (a lens calibrated elsewhere) instead of "
                  "estimating it");
    sub->add_flag("--estimate-depth-scale", opt->estimate_depth_scale,
                  "also estimate the depth scale (only observable with references at several "
                  "distances; held at the recorded value otherwise)");
    sub->callback([&run, opt] { run = [opt] { return RunCalibrate(*opt); }; });
}

}  // namespace boxd::cli
