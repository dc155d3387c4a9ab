// `boxd serve` on a full disk (a small tmpfs as the data folder, mounted where the test runs as
// root): a measurement that cannot be stored is not reported as stored, and the daemon measures
// and stores again once there is room.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A tmpfs of `size` mounted at `dir`, unmounted when the object goes away.
class SmallDisk {
public:
    SmallDisk(const fs::path& dir, const std::string& size) : dir_(dir) {
        fs::create_directories(dir);
        mounted_ = ::geteuid() == 0 &&
                   ::mount("tmpfs", dir.c_str(), "tmpfs", 0, ("size=" + size).c_str()) == 0;
    }
    ~SmallDisk() {
        if (mounted_) ::umount2(dir_.c_str(), MNT_DETACH);
    }
    bool mounted() const { return mounted_; }

private:
    fs::path dir_;
    bool mounted_ = false;
};

// Fills `dir` with one file until writing fails (the disk is full), and returns its path.
fs::path FillUp(const fs::path& dir) {
    const fs::path filler = dir / "filler";
    std::ofstream out(filler, std::ios::binary);
    const std::string block(64 * 1024, 'x');
    while (out.write(block.data(), static_cast<std::streamsize>(block.size()))) out.flush();
    return filler;
}

TEST(ServeFullDisk, AResultThatCannotBeStoredIsNotReportedAsStored) {
    test::TempDir dir;
    SmallDisk disk(dir / "data", "24m");
    if (!disk.mounted()) GTEST_SKIP() << "needs root and tmpfs mounts (mount(2) refused)";
    test::ServeDaemon daemon(test::SimConfigPath(), dir / "data", dir / "serve.log");
    ASSERT_TRUE(daemon.WaitHealthy());
    auto first = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(first);
    ASSERT_EQ(first->status, 200) << first->body;

    // Room for the database's few rows but not for the fused cloud: the measurement runs and its
    // result cannot be stored.
    const fs::path filler = FillUp(dir / "data");
    fs::resize_file(filler, fs::file_size(filler) - 256 * 1024);
    auto full = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(full);
    EXPECT_EQ(full->status, 507) << full->body;
    EXPECT_FALSE(full->has_header("Location"));
    const json j = json::parse(full->body);
    EXPECT_EQ(j["status"], "failed");
    EXPECT_EQ(j["reason"]["code"], "STORAGE_ERROR");
    EXPECT_TRUE(j["dimensions"].is_null());
    // A client polling that id hears the same, not a bare 404.
    const json polled = daemon.GetJson("/v1/measurements/" + j["id"].get<std::string>());
    EXPECT_EQ(polled["reason"]["code"], "STORAGE_ERROR") << polled.dump();
    // The last stored measurement is still the first one.
    EXPECT_EQ(daemon.GetJson("/v1/measurements/last")["id"], json::parse(first->body)["id"]);

    // No room at all: not even an id is given out, and nothing says it was.
    std::ofstream(dir / "data" / "filler2", std::ios::binary) << std::string(512 * 1024, 'x');
    auto none = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(none);
    EXPECT_GE(none->status, 500) << none->body;
    EXPECT_FALSE(none->has_header("Location"));
    EXPECT_EQ(json::parse(none->body)["error"]["code"], "STORAGE_ERROR") << none->body;

    // Room again: measured and stored.
    fs::remove(filler);
    fs::remove(dir / "data" / "filler2");
    auto again = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(again);
    EXPECT_EQ(again->status, 200) << again->body;
    const std::string id = json::parse(again->body)["id"].get<std::string>();
    EXPECT_EQ(daemon.GetJson("/v1/measurements/" + id)["status"], "ok");
}

}  // namespace
}  // namespace boxd
