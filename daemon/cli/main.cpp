// boxd: parcel dimensioner. Parses the command line and runs one subcommand.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "daemon/cli/cli.h"

int main(int argc, char** argv) {
    using namespace boxd::cli;
    using boxd::Error;
    using boxd::ErrorCode;
    SetupLogging();
    CLI::App app{"boxd: measures parcels on a turntable with a depth camera"};
    app.name("boxd");
    app.require_subcommand(1, 1);
    Runner run;
    AddServe(app, run);
    AddMeasure(app, run);
    AddCalibrate(app, run);
    AddRecord(app, run);
    AddSynth(app, run);
    AddSimTurntable(app, run);
    AddDevices(app, run);
    AddBenchMeasure(app, run);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help
        return Fail(Error{ErrorCode::kInvalidInput, std::string(e.what()) + " (see boxd --help)"});
    }
    try {
        return run ? run() : Fail(Error{ErrorCode::kInvalidInput, "no subcommand"});
    } catch (const std::exception& e) {
        return Fail(Error{ErrorCode::kInternal, std::string("internal failure: ") + e.what()});
    }
}
