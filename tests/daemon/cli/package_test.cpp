// The Debian package, built the way the README says (`cpack -G DEB` in the build folder) and
// read back with dpkg-deb: its name and version, its dependencies, the files a station needs
// (binary, unit, conffile, templates, operator page, man page, copyright, changelog), the
// maintainer scripts that add the `boxd` user and register the unit as debhelper does, a
// packaged binary that runs, and lintian's verdict: no error, no warning. One test: cpack runs
// once.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "tests/support/run_command.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;

std::string Field(const fs::path& deb, const std::string& name) {
    const auto out = test::RunCommand({"dpkg-deb", "-f", deb.string(), name});
    EXPECT_EQ(out.exit_code, 0) << out.err;
    return out.out.substr(0, out.out.find_last_not_of('\n') + 1);
}

std::string ReadAll(const fs::path& path) {
    std::ifstream in(path);
    return std::string((std::istreambuf_iterator<char>(in)), {});
}

void CheckControl(const fs::path& deb) {
    EXPECT_EQ(Field(deb, "Package"), "boxd");
    EXPECT_EQ(Field(deb, "Version"), BOXD_TEST_VERSION);
    EXPECT_EQ(Field(deb, "Architecture"), "amd64");
    const std::string depends = Field(deb, "Depends");
    for (const char* lib :
         {"adduser", "libmodbus5", "libmosquitto1", "libopenni2-0", "libfreenect0.5",
          "libusb-1.0-0", "libsystemd0", "libsqlite3-0", "libjs-three"}) {
        EXPECT_NE(depends.find(lib), std::string::npos) << lib << " not in: " << depends;
    }
}

void CheckContents(const fs::path& deb, const fs::path& root) {
    const auto list = test::RunCommand({"dpkg-deb", "-c", deb.string()});
    ASSERT_EQ(list.exit_code, 0) << list.err;
    const struct {
        const char* path;
        const char* mode;
    } expected[] = {
        {"./usr/bin/boxd", "-rwxr-xr-x"},
        {"./usr/lib/systemd/system/boxd.service", "-rw-r--r--"},
        {"./usr/lib/udev/rules.d/60-boxd-depth-cameras.rules", "-rw-r--r--"},
        {"./etc/boxd/boxd.yaml", "-rw-r--r--"},  // postinst makes it 0640 (below)
        {"./usr/share/boxd/config/boxd.yaml", "-rw-r--r--"},
        {"./usr/share/boxd/config/sim.yaml", "-rw-r--r--"},
        {"./usr/share/boxd/web/index.html", "-rw-r--r--"},
        {"./usr/share/boxd/web/page.js", "-rw-r--r--"},
        {"./usr/share/boxd/web/cloud_view.js", "-rw-r--r--"},
        {"./usr/share/boxd/web/page.css", "-rw-r--r--"},
        // The README and the documentation it links.
        {"./usr/share/doc/boxd/README.md", "-rw-r--r--"},
        {"./usr/share/doc/boxd/docs/station.md", "-rw-r--r--"},
        {"./usr/share/doc/boxd/docs/findings/README.md", "-rw-r--r--"},
        {"./usr/share/doc/boxd/copyright", "-rw-r--r--"},
        {"./usr/share/doc/boxd/changelog.gz", "-rw-r--r--"},
        {"./usr/share/man/man1/boxd.1.gz", "-rw-r--r--"},
    };
    for (const auto& e : expected) {
        const std::regex line(std::string("(^|\\n)") + e.mode + R"( root/root +\d+ \S+ \S+ )" +
                              std::regex_replace(e.path, std::regex(R"([.])"), R"(\.)") + "\n");
        EXPECT_TRUE(std::regex_search(list.out, line)) << e.path << " " << e.mode << " in:\n"
                                                       << list.out;
    }
    ASSERT_EQ(test::RunCommand({"dpkg-deb", "-x", deb.string(), root.string()}).exit_code, 0);
    const std::string unit = ReadAll(root / "usr/lib/systemd/system/boxd.service");
    EXPECT_NE(unit.find("ExecStart=/usr/bin/boxd serve --config /etc/boxd/boxd.yaml"),
              std::string::npos);
    EXPECT_NE(unit.find("User=boxd"), std::string::npos);
    EXPECT_NE(unit.find("\nDocumentation=man:boxd(1) "), std::string::npos);
    // The man page holds every subcommand's options.
    const auto man =
        test::RunCommand({"sh", "-c", "zcat " + (root / "usr/share/man/man1/boxd.1.gz").string()});
    EXPECT_NE(man.out.find(".SS \"boxd measure\""), std::string::npos) << man.out;
    EXPECT_NE(man.out.find("--reference"), std::string::npos);
    // Stripped: no symbol table, no debug sections.
    const auto sections = test::RunCommand({"readelf", "-S", (root / "usr/bin/boxd").string()});
    EXPECT_EQ(sections.out.find(".symtab"), std::string::npos);
    EXPECT_EQ(sections.out.find(".debug_"), std::string::npos);
    const auto help = test::RunCommand({(root / "usr/bin/boxd").string(), "--help"});
    EXPECT_EQ(help.exit_code, 0) << help.err;
    EXPECT_NE(help.out.find("serve"), std::string::npos);
}

void CheckMaintainerScripts(const fs::path& deb, const fs::path& control) {
    ASSERT_EQ(test::RunCommand({"dpkg-deb", "-e", deb.string(), control.string()}).exit_code, 0);
    EXPECT_EQ(ReadAll(control / "conffiles"), "/etc/boxd/boxd.yaml\n");
    const std::string postinst = ReadAll(control / "postinst");
    EXPECT_NE(postinst.find("adduser --system --group"), std::string::npos) << postinst;
    EXPECT_NE(postinst.find("dialout"), std::string::npos);
    // The config may come to hold the bearer token: not world-readable once installed.
    EXPECT_NE(postinst.find("chmod 0640 /etc/boxd/boxd.yaml"), std::string::npos) << postinst;
    EXPECT_NE(ReadAll(control / "prerm").find("deb-systemd-invoke stop boxd.service"),
              std::string::npos);
    EXPECT_NE(postinst.find("deb-systemd-helper update-state boxd.service"), std::string::npos);
    EXPECT_NE(ReadAll(control / "postrm").find("deb-systemd-helper purge boxd.service"),
              std::string::npos);
    EXPECT_EQ(fs::status(control / "postinst").permissions() & fs::perms::all, fs::perms(0755));
    for (const char* script : {"postinst", "prerm", "postrm"}) {
        const auto syntax = test::RunCommand({"sh", "-n", (control / script).string()});
        EXPECT_EQ(syntax.exit_code, 0) << script << ": " << syntax.err;
    }
}

// Lintian, as Debian's archive runs it: every error and warning fails (pedantic and
// experimental tags are not asked for).
void CheckLintian(const fs::path& deb) {
    const auto lintian =
        test::RunCommand({"lintian", "--fail-on", "error,warning", "--display-info",
                          "--no-tag-display-limit", deb.string()});
    EXPECT_EQ(lintian.exit_code, 0) << lintian.out << lintian.err;
    EXPECT_EQ(lintian.out.find("E: "), std::string::npos) << lintian.out;
    EXPECT_EQ(lintian.out.find("W: "), std::string::npos) << lintian.out;
    for (const char* tag : {"hardening-no-bindnow", "hardening-no-fortify-functions",
                            "systemd-service-file-missing-documentation-key"}) {
        EXPECT_EQ(lintian.out.find(tag), std::string::npos) << tag << ":\n" << lintian.out;
    }
}

TEST(DebianPackage, HoldsWhatAStationNeedsAndAddsItsUser) {
    test::TempDir dir;
    const auto built = test::RunCommand({"cpack", "-G", "DEB", "--config",
                                         std::string(BOXD_BUILD_DIR) + "/CPackConfig.cmake", "-B",
                                         dir.path().string()});
    ASSERT_EQ(built.exit_code, 0) << built.out << built.err;
    const fs::path deb = dir / ("boxd_" BOXD_TEST_VERSION "_amd64.deb");
    ASSERT_TRUE(fs::exists(deb)) << built.out;
    {
        SCOPED_TRACE("control");
        CheckControl(deb);
    }
    {
        SCOPED_TRACE("contents");
        CheckContents(deb, dir / "root");
    }
    {
        SCOPED_TRACE("maintainer scripts");
        CheckMaintainerScripts(deb, dir / "control");
    }
    {
        SCOPED_TRACE("lintian");
        CheckLintian(deb);
    }
}

}  // namespace
}  // namespace boxd
