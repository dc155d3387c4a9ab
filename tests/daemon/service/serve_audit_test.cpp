// The audit trail through the real daemon on the simulated station (config/sim.yaml): the
// software identified in /v1/status and every result, the event counter rising on POST
// /v1/calibrate and on a changed billing section after a restart and never falling, and a
// record edited in the store found by `boxd verify` and at start.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <thread>

#include "daemon/service/sha256.h"
#include "tests/support/run_command.h"
#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// config/sim.yaml with the express divisor replaced, written into `dir`.
fs::path SimConfig(const fs::path& dir, int express_divisor) {
    std::string text = test::ReadText(test::SimConfigPath());
    text = std::regex_replace(text, std::regex("express: 5000"),
                              "express: " + std::to_string(express_divisor));
    const fs::path path = dir / ("sim-" + std::to_string(express_divisor) + ".yaml");
    std::ofstream(path) << text;
    return path;
}

json Audit(test::ServeDaemon& daemon) { return daemon.GetJson("/v1/status")["audit"]; }

// Waits (a few loop ticks at most) for the event counter to reach `n`.
json AuditWithCounter(test::ServeDaemon& daemon, long long n) {
    json audit;
    for (int i = 0; i < 50; ++i) {
        audit = Audit(daemon);
        if (audit["event_counter"] == n) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return audit;
}

TEST(ServeAudit, IdentifiesItsSoftwareInStatusAndEveryResult) {
    test::TempDir dir;
    test::ServeDaemon daemon(test::SimConfigPath(), dir.path() / "data", dir.path() / "boxd.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir.path() / "boxd.log");
    const json audit = Audit(daemon);
    auto sha = Sha256OfFile(BOXD_BINARY);
    ASSERT_TRUE(sha);
    EXPECT_EQ(audit["software"]["sha256"], *sha);
    EXPECT_FALSE(audit["software"]["version"].get<std::string>().empty());
    EXPECT_EQ(audit["event_counter"], 0);
    EXPECT_EQ(audit["records"]["intact"], true);
    auto res = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    EXPECT_EQ(json::parse(res->body)["software"], audit["software"]);
    // The head /v1/status publishes is the newest record's, as it is now.
    const std::string head = Audit(daemon)["records"]["head"];
    EXPECT_NE(head, audit["records"]["head"].get<std::string>());
    const auto verified = test::RunBoxd({"verify", "--data-dir", (dir.path() / "data").string()});
    ASSERT_EQ(verified.exit_code, 0) << verified.err;
    EXPECT_EQ(json::parse(verified.out)["records"]["head"], head);
    const std::string metrics = daemon.client().Get("/metrics")->body;
    EXPECT_NE(metrics.find("\nboxd_metrological_events_total 0\n"), std::string::npos) << metrics;
    EXPECT_NE(metrics.find("\nboxd_stored_records_intact 1\n"), std::string::npos) << metrics;
}

TEST(ServeAudit, CountsACalibrationAndAChangedBillingAndNeverFalls) {
    test::TempDir dir;
    const fs::path data = dir.path() / "data", log = dir.path() / "boxd.log";
    // Both written before the calibration: a config file newer than the stored calibration
    // would put its own calibration section back in force (another event).
    const fs::path express_5000 = SimConfig(dir.path(), 5000);
    const fs::path express_4000 = SimConfig(dir.path(), 4000);
    {
        test::ServeDaemon daemon(express_5000, data, log);
        ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(log);
        EXPECT_EQ(Audit(daemon)["event_counter"], 0);
        auto calibrated = daemon.client().Post(
            "/v1/calibrate", R"({"reference_m": [0.455, 0.33, 0.46]})", "application/json");
        ASSERT_TRUE(calibrated);
        ASSERT_EQ(calibrated->status, 200) << calibrated->body;
        const json audit = AuditWithCounter(daemon, 1);
        ASSERT_EQ(audit["event_counter"], 1) << audit.dump();
        EXPECT_EQ(audit["last_event"]["what"], "calibration");
        EXPECT_EQ(audit["last_event"]["via"], "POST /v1/calibrate");
    }
    {
        // The same station restarted with another express divisor.
        test::ServeDaemon daemon(express_4000, data, log);
        ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(log);
        const json audit = Audit(daemon);
        EXPECT_EQ(audit["event_counter"], 2) << audit.dump();
        EXPECT_EQ(audit["last_event"]["what"], "billing");
        EXPECT_NE(audit["last_event"]["from"].get<std::string>().find("\"express\":\"5000\""),
                  std::string::npos);
        EXPECT_NE(audit["last_event"]["to"].get<std::string>().find("\"express\":\"4000\""),
                  std::string::npos);
        EXPECT_NE(audit["last_event"]["via"].get<std::string>().find("at start"),
                  std::string::npos);
        const json events = daemon.GetJson("/v1/audit");
        ASSERT_EQ(events["events"].size(), 2u) << events.dump();
        EXPECT_EQ(events["events"][1]["what"], "calibration");
    }
    {
        // Unchanged: no event; the counter stays where it is.
        test::ServeDaemon daemon(express_4000, data, log);
        ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(log);
        EXPECT_EQ(Audit(daemon)["event_counter"], 2);
    }
}

TEST(ServeAudit, AnEditedRecordIsFoundByVerifyAndAtStart) {
    test::TempDir dir;
    const fs::path data = dir.path() / "data", log = dir.path() / "boxd.log";
    std::string first;
    {
        test::ServeDaemon daemon(test::SimConfigPath(), data, log);
        ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(log);
        for (int i = 0; i < 2; ++i) {
            auto res = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
            ASSERT_TRUE(res);
            if (i == 0) first = json::parse(res->body)["id"];
        }
    }
    const auto intact = test::RunBoxd({"verify", "--data-dir", data.string()});
    EXPECT_EQ(intact.exit_code, 0) << intact.err;
    EXPECT_EQ(json::parse(intact.out)["records"]["checked"], 2);
    // The first record's length made 5 mm shorter with a database tool.
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((data / "boxd.db").c_str(), &db), SQLITE_OK);
    const std::string sql =
        "UPDATE measurements SET result_json = replace(result_json, '\"length_m\":0.45', "
        "'\"length_m\":0.44') WHERE id = '" +
        first + "';";
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
    EXPECT_EQ(sqlite3_changes(db), 1);
    sqlite3_close(db);

    const auto broken = test::RunBoxd({"verify", "--data-dir", data.string()});
    EXPECT_EQ(broken.exit_code, 4) << broken.err;
    const json report = json::parse(broken.out);
    EXPECT_EQ(report["records"]["intact"], false);
    EXPECT_EQ(report["records"]["problem"], first + " was changed after it was stored");
    EXPECT_NE(broken.err.find(first), std::string::npos) << broken.err;

    test::ServeDaemon daemon(test::SimConfigPath(), data, log);
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(log);
    const json audit = Audit(daemon);
    EXPECT_EQ(audit["records"]["intact"], false) << audit.dump();
    EXPECT_EQ(audit["records"]["problem"], first + " was changed after it was stored");
    EXPECT_NE(test::ReadText(log).find("the hash chain is broken: " + first), std::string::npos);

    const auto missing = test::RunBoxd({"verify", "--data-dir", (dir.path() / "none").string()});
    EXPECT_EQ(missing.exit_code, 2) << missing.err;
}

}  // namespace
}  // namespace boxd
