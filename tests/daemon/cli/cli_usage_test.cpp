// The command line before any subcommand runs, through the real binary: `--version` names the
// release, the commit and the build type; a bare `boxd` prints its usage; an unknown command or
// option is named as such with the nearest valid one; the help points at documentation that is
// shipped.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "tests/support/run_command.h"

namespace boxd {
namespace {

using test::RunBoxd;

TEST(CliUsage, VersionNamesTheReleaseTheCommitAndTheBuildType) {
    const auto r = RunBoxd({"--version"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_match(
        r.out, m,
        std::regex(
            R"(boxd (\d+\.\d+\.\d+) \(commit ([0-9a-f]{12}(-dirty)?|unknown), (\w+) build\)\n)")))
        << r.out;
    EXPECT_EQ(m[1], BOXD_TEST_VERSION);
    // The commit of the source tree it was built from, when that is a git checkout.
    const auto head = test::RunCommand(
        {"/usr/bin/git", "-C", BOXD_SOURCE_DIR, "rev-parse", "--short=12", "HEAD"});
    if (head.exit_code == 0) {
        EXPECT_EQ(m[2].str().substr(0, 12), head.out.substr(0, 12));
    }
}

TEST(CliUsage, ABareBoxdPrintsItsUsageAndExits2) {
    const auto r = RunBoxd({});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("Usage: boxd [OPTIONS] SUBCOMMAND"), std::string::npos) << r.err;
    for (const char* command : {"serve", "measure", "calibrate", "record", "synth"}) {
        EXPECT_NE(r.err.find(std::string("  ") + command), std::string::npos) << command;
    }
}

TEST(CliUsage, AnUnknownCommandIsNamedWithTheNearestOne) {
    const auto slip = RunBoxd({"mesure", "--session", "x"});
    EXPECT_EQ(slip.exit_code, 2);
    EXPECT_NE(slip.err.find("unknown command 'mesure' (did you mean measure?)"), std::string::npos)
        << slip.err;
    const auto far = RunBoxd({"frobnicate"});
    EXPECT_EQ(far.exit_code, 2);
    EXPECT_NE(far.err.find("unknown command 'frobnicate'; the commands are serve, measure"),
              std::string::npos)
        << far.err;
    EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
    const auto option = RunBoxd({"--verison"});
    EXPECT_EQ(option.exit_code, 2);
    EXPECT_NE(option.err.find("unknown option --verison (did you mean --version?)"),
              std::string::npos)
        << option.err;
}

TEST(CliUsage, AnUnknownOptionIsNamedBeforeAnyMissingOne) {
    const auto bogus = RunBoxd({"measure", "--bogus"});
    EXPECT_EQ(bogus.exit_code, 2);
    EXPECT_NE(bogus.err.find("boxd measure: unknown option --bogus (see boxd measure --help)"),
              std::string::npos)
        << bogus.err;
    EXPECT_EQ(bogus.err.find("--session is required"), std::string::npos) << bogus.err;
    const auto slip = RunBoxd({"calibrate", "--sesion=x", "--reference", "1", "1", "1"});
    EXPECT_EQ(slip.exit_code, 2);
    EXPECT_NE(slip.err.find("unknown option --sesion (did you mean --session?)"), std::string::npos)
        << slip.err;
    // Values after "--" and negative numbers are not options.
    const auto values = RunBoxd({"synth", "--out", "/nonexistent/x", "--dims", "0.3", "0.2", "0.1",
                                 "--yaw", "-20", "--seed", "1"});
    EXPECT_EQ(values.err.find("unknown option"), std::string::npos) << values.err;
}

TEST(CliUsage, TheHelpPointsAtShippedDocumentation) {
    for (const char* command : {"serve", "measure", "calibrate", "record", "synth", "sim-turntable",
                                "devices", "bench-measure", "import-dump"}) {
        const auto r = RunBoxd({command, "--help"});
        EXPECT_EQ(r.exit_code, 0) << command;
        EXPECT_EQ(r.out.find("SPEC"), std::string::npos) << command << ": " << r.out;
    }
    EXPECT_NE(RunBoxd({"serve", "--help"}).out.find("docs/daemon.md"), std::string::npos);
}

}  // namespace
}  // namespace boxd
