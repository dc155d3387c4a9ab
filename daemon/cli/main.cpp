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
    CLI::App app{
        "boxd: measures parcels on a turntable with a depth camera. The documentation: "
        "README.md and docs/ (installed in /usr/share/doc/boxd), man boxd."};
    app.name("boxd");
    app.require_subcommand(1, 1);
    app.set_version_flag("--version", VersionText(), "print the version, commit and build type");
    Runner run;
    AddServe(app, run);
    AddMeasure(app, run);
    AddCalibrate(app, run);
    AddRecord(app, run);
    AddSynth(app, run);
    AddSimTurntable(app, run);
    AddDevices(app, run);
    AddBenchMeasure(app, run);
    AddVerify(app, run);
    AddExport(app, run);
    AddImportDump(app, run);
    if (argc < 2) {
        // A bare `boxd`: how to use it, on stderr with the exit code of bad usage.
        std::fprintf(stderr, "%s", app.help().c_str());
        return ExitCodeOf(ErrorCode::kInvalidInput);
    }
    if (auto wrong = CheckArguments(app, argc, argv)) return Fail(*wrong);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
        return Fail(Error{ErrorCode::kInvalidInput, std::string(e.what()) + " (see boxd --help)"});
    }
    try {
        return run ? run() : Fail(Error{ErrorCode::kInvalidInput, "no subcommand"});
    } catch (const std::exception& e) {
        return Fail(Error{ErrorCode::kInternal, std::string("internal failure: ") + e.what()});
    }
}
