// The daemon's calibration history: the `calibrations` table on its own (a real SQLite file),
// and through `boxd serve` on the simulated station (config/sim.yaml): every POST /v1/calibrate,
// refused or not, appears in GET /v1/calibration's "history", newest first, across a restart.
#include "daemon/service/calibration_history.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

CalibrationRecord Refused(const std::string& at, ErrorCode code) {
    CalibrationRecord r;
    r.finished_at = at;
    r.error = Error{code, std::string("refused at ").append(at)};
    r.reference = {0.3, 0.2, 0.1};
    return r;
}

TEST(CalibrationHistoryStore, KeepsEveryCalibrationNewestFirstAcrossReopen) {
    test::TempDir dir;
    {
        auto history = CalibrationHistory::Open(dir.path());
        ASSERT_TRUE(history.ok()) << history.error().message;
        auto empty = (*history)->List(20);
        ASSERT_TRUE(empty.ok());
        EXPECT_TRUE(empty->empty());

        ASSERT_TRUE((*history)->Record(Refused("2026-01-01T00:00:00Z", ErrorCode::kBoxMoved)).ok());
        CalibrationRecord ok;
        ok.finished_at = "2026-01-01T00:01:00Z";
        ok.reference = {0.32, 0.26, 0.30};
        ok.report = CalibrationReport{};
        ok.report->table_rms_m = 0.0012;
        ok.report->face_rms_m = 0.0015;
        ok.report->calibration.depth_offset_m = 0.01;
        ok.report->calibration.depth_scale = 1.0;
        ASSERT_TRUE((*history)->Record(ok).ok());
    }
    auto history = CalibrationHistory::Open(dir.path());  // what was committed is still there
    ASSERT_TRUE(history.ok());
    auto list = (*history)->List(20);
    ASSERT_TRUE(list.ok());
    ASSERT_EQ(list->size(), 2u);
    const json& newest = (*list)[0];
    EXPECT_EQ(newest["finished_at"], "2026-01-01T00:01:00Z");
    EXPECT_EQ(newest["status"], "ok");
    EXPECT_TRUE(newest["error"].is_null());
    EXPECT_EQ(newest["quality"]["face_rms_m"], 0.0015);
    EXPECT_EQ(newest["calibration"]["depth_offset_m"], 0.01);
    EXPECT_EQ(newest["reference_m"], json({0.32, 0.26, 0.30}));
    const json& oldest = (*list)[1];
    EXPECT_EQ(oldest["status"], "failed");
    EXPECT_EQ(oldest["error"]["code"], "BOX_MOVED");
    EXPECT_EQ(oldest["error"]["message"], "refused at 2026-01-01T00:00:00Z");
    EXPECT_TRUE(oldest["quality"].is_null());
    EXPECT_TRUE(oldest["calibration"].is_null());

    auto one = (*history)->List(1);
    ASSERT_TRUE(one.ok());
    ASSERT_EQ(one->size(), 1u);
    EXPECT_EQ((*one)[0]["status"], "ok");
}

TEST(CalibrationHistoryStore, KeepsOnlyTheLatest) {
    test::TempDir dir;
    auto history = CalibrationHistory::Open(dir.path());
    ASSERT_TRUE(history.ok());
    const int total = CalibrationHistory::kKept + 5;
    // Timestamps are the record's index (sortable text is all the table needs).
    for (int i = 0; i < total; ++i) {
        ASSERT_TRUE(
            (*history)->Record(Refused(std::to_string(1000 + i), ErrorCode::kNoReference)).ok());
    }
    auto list = (*history)->List(1000);
    ASSERT_TRUE(list.ok());
    ASSERT_EQ(static_cast<int>(list->size()), CalibrationHistory::kKept);
    EXPECT_EQ(list->front()["finished_at"], std::to_string(1000 + total - 1));
    EXPECT_EQ(list->back()["finished_at"], "1005");
}

using test::ReadText;

// `boxd serve` on the simulated station.
class Daemon : public test::ServeDaemon {
public:
    Daemon(const fs::path& data_dir, const fs::path& log)
        : ServeDaemon(test::SimConfigPath(), data_dir, log) {}
};

// config/sim.yaml's box is 0.455 x 0.33 x 0.46 m.
TEST(ServeCalibrationHistory, EveryCalibrationIsListedNewestFirstAcrossARestart) {
    test::TempDir dir;
    const fs::path data = dir / "data";
    const fs::path log = dir / "serve.log";
    {
        Daemon daemon(data, log);
        ASSERT_TRUE(daemon.WaitHealthy()) << ReadText(log);
        const json before = daemon.GetJson("/v1/calibration");
        EXPECT_EQ(before["calibrated"], true) << before.dump();  // sim.yaml has a calibration
        // ... whose section does not say when it was made: no age is made up.
        EXPECT_TRUE(before["calibrated_at"].is_null()) << before.dump();
        EXPECT_TRUE(before["age_s"].is_null()) << before.dump();
        EXPECT_TRUE(before["run"].is_null()) << before.dump();
        ASSERT_TRUE(before["history"].is_array()) << before.dump();
        EXPECT_TRUE(before["history"].empty()) << before.dump();

        // A reference 30% longer than the box on the table: refused, and recorded as such.
        auto wrong = daemon.client().Post("/v1/calibrate", R"({"reference_m": [0.6, 0.33, 0.46]})",
                                          "application/json");
        ASSERT_TRUE(wrong) << httplib::to_string(wrong.error());
        ASSERT_EQ(wrong->status, 422) << wrong->body;
        auto right = daemon.client().Post(
            "/v1/calibrate", R"({"reference_m": [0.455, 0.33, 0.46]})", "application/json");
        ASSERT_TRUE(right) << httplib::to_string(right.error());
        ASSERT_EQ(right->status, 200) << right->body << ReadText(log);
        const json report = json::parse(right->body);

        const json after = daemon.GetJson("/v1/calibration");
        // The SPEC fields are still there, now the new calibration's.
        EXPECT_EQ(after["calibrated"], true);
        EXPECT_EQ(after["depth_offset_m"], report["calibration"]["depth_offset_m"]);
        // Its age is the run's: made moments ago, with this reference and these figures.
        EXPECT_EQ(after["calibrated_at"], report["calibrated_at"]) << after.dump();
        EXPECT_GE(after["age_s"].get<long long>(), 0);
        EXPECT_LT(after["age_s"].get<long long>(), 120);
        EXPECT_EQ(after["run"]["reference_m"], json({0.455, 0.33, 0.46}));
        EXPECT_EQ(after["run"]["quality"], report["quality"]);
        const json& history = after["history"];
        ASSERT_EQ(history.size(), 2u) << after.dump(2);
        EXPECT_EQ(history[0]["status"], "ok");
        EXPECT_TRUE(history[0]["error"].is_null());
        EXPECT_EQ(history[0]["calibration"], report["calibration"]);
        EXPECT_EQ(history[0]["quality"]["table_rms_m"], report["quality"]["table_rms_m"]);
        EXPECT_GT(history[0]["quality"]["face_rms_m"].get<double>(), 0.0);
        EXPECT_EQ(history[0]["reference_m"], json({0.455, 0.33, 0.46}));
        EXPECT_EQ(history[1]["status"], "failed");
        EXPECT_EQ(history[1]["error"]["code"], "WRONG_REFERENCE");
        EXPECT_TRUE(history[1]["calibration"].is_null());
        EXPECT_GE(history[0]["finished_at"].get<std::string>(),
                  history[1]["finished_at"].get<std::string>());
    }
    Daemon again(data, log);
    ASSERT_TRUE(again.WaitHealthy()) << ReadText(log);
    const json restored = again.GetJson("/v1/calibration");
    EXPECT_FALSE(restored["calibrated_at"].is_null()) << restored.dump();  // kept across starts
    EXPECT_GE(restored["age_s"].get<long long>(), 0);
    const json history = restored["history"];
    ASSERT_EQ(history.size(), 2u) << history.dump();
    EXPECT_EQ(history[0]["status"], "ok");
    EXPECT_EQ(history[1]["error"]["code"], "WRONG_REFERENCE");
}

}  // namespace
}  // namespace boxd
