// The REST API over real TCP (httplib::Client), in-process, with a station of the test's own so
// every state (busy, finished, failed) can be reached on demand (the server's access and its
// defences: http_server_guards_test.cpp).
#include "daemon/service/http_api.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <thread>

#include "tests/support/http_api_fixture.h"
#include "tests/support/prometheus_text.h"

namespace boxd {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;
using test::HttpApiTest;

TEST_F(HttpApiTest, HealthAndIdleStatus) {
    auto health = client_->Get("/v1/health");
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
    EXPECT_EQ(Body(health), json({{"status", "ok"}}));
    auto status = client_->Get("/v1/status");
    ASSERT_TRUE(status);
    EXPECT_EQ(status->status, 200);
    const json s = Body(status);
    EXPECT_EQ(s["state"], "idle");
    EXPECT_TRUE(s["progress"].is_null());
    EXPECT_TRUE(s["last_error"].is_null());
    EXPECT_EQ(s["calibration_age_s"], 42);
    EXPECT_EQ(s["devices"]["turntable"]["ok"], true);
}

TEST_F(HttpApiTest, NoMeasurementYetIs404) {
    ExpectError(client_->Get("/v1/measurements/last"), 404, "NOT_FOUND");
    ExpectError(client_->Get("/v1/measurements/m-000001"), 404, "NOT_FOUND");
    ExpectError(client_->Get("/v1/measurements/m-000001/cloud.ply"), 404, "NOT_FOUND");
    auto list = client_->Get("/v1/measurements");
    ASSERT_TRUE(list);
    EXPECT_EQ(list->status, 200);
    EXPECT_TRUE(Body(list)["measurements"].empty());
}

TEST_F(HttpApiTest, MeasureWaitReturnsTheResultAndItIsStored) {
    auto res = client_->Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    const json m = Body(res);
    EXPECT_EQ(m["id"], "m-000001");
    EXPECT_EQ(m["status"], "ok");
    EXPECT_DOUBLE_EQ(m["dimensions"]["length_m"].get<double>(), 0.4);
    EXPECT_TRUE(m["timing_ms"].contains("total"));

    auto last = client_->Get("/v1/measurements/last");
    ASSERT_TRUE(last);
    EXPECT_EQ(last->status, 200);
    EXPECT_EQ(Body(last), m);
    auto by_id = client_->Get("/v1/measurements/m-000001");
    ASSERT_TRUE(by_id);
    EXPECT_EQ(Body(by_id), m);
    auto cloud = client_->Get("/v1/measurements/m-000001/cloud.ply");
    ASSERT_TRUE(cloud);
    EXPECT_EQ(cloud->status, 200);
    EXPECT_EQ(cloud->body.rfind("ply\n", 0), 0u);
}

TEST_F(HttpApiTest, MeasureReturns202ThenSecondPostIs409WhileBusy) {
    station_->hold = true;
    auto first = client_->Post("/v1/measure", "", "application/json");
    ASSERT_TRUE(first);
    ASSERT_EQ(first->status, 202) << first->body;
    const std::string id = Body(first)["id"];
    EXPECT_EQ(id, "m-000001");
    EXPECT_EQ(first->get_header_value("Location"), "/v1/measurements/" + id);

    for (int i = 0; i < 1000 && !station_->in_capture; ++i) std::this_thread::sleep_for(2ms);
    ExpectError(client_->Post("/v1/measure", "", "application/json"), 409, "BUSY");
    ExpectError(client_->Post("/v1/measure?wait=1", "", "application/json"), 409, "BUSY");

    // GETs keep answering during the measurement, with its progress.
    auto status = client_->Get("/v1/status");
    ASSERT_TRUE(status);
    const json s = Body(status);
    EXPECT_EQ(s["state"], "measuring");
    EXPECT_EQ(s["measurement_id"], id);
    EXPECT_EQ(s["progress"]["pose"], 1);
    EXPECT_EQ(s["progress"]["poses"], 4);
    auto health = client_->Get("/v1/health");
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
    ExpectError(client_->Get("/v1/measurements/" + id), 404, "NOT_FOUND");  // not finished

    station_->hold = false;
    WaitUntilIdle();
    auto done = client_->Get("/v1/measurements/" + id);
    ASSERT_TRUE(done);
    EXPECT_EQ(done->status, 200);
    EXPECT_EQ(Body(done)["status"], "ok");
    auto next = client_->Post("/v1/measure", "", "application/json");
    ASSERT_TRUE(next);
    EXPECT_EQ(next->status, 202);
    EXPECT_EQ(Body(next)["id"], "m-000002");
}

TEST_F(HttpApiTest, HistoryIsNewestFirstWithLimit) {
    for (int i = 0; i < 3; ++i) {
        auto res = client_->Post("/v1/measure?wait=1", "", "application/json");
        ASSERT_TRUE(res);
        ASSERT_EQ(res->status, 200);
    }
    auto list = client_->Get("/v1/measurements?limit=2");
    ASSERT_TRUE(list);
    ASSERT_EQ(list->status, 200);
    const json l = Body(list)["measurements"];
    ASSERT_EQ(l.size(), 2u);
    EXPECT_EQ(l[0]["id"], "m-000003");
    EXPECT_EQ(l[1]["id"], "m-000002");
    for (const char* bad : {"0", "-1", "abc", "5x", "100000"}) {
        ExpectError(client_->Get(std::string("/v1/measurements?limit=") + bad), 400, "BAD_REQUEST");
    }
}

TEST_F(HttpApiTest, BadRequestsGetTheirCodesAndTheDaemonKeepsServing) {
    ExpectError(client_->Post("/v1/measure", "{not json", "application/json"), 400, "BAD_REQUEST");
    ExpectError(client_->Post("/v1/measure", "[1,2]", "application/json"), 400, "BAD_REQUEST");
    ExpectError(client_->Post("/v1/measure?wait=maybe", "", "application/json"), 400,
                "BAD_REQUEST");
    ExpectError(client_->Get("/v1/nope"), 404, "NOT_FOUND");
    ExpectError(client_->Get("/index.html"), 404, "NOT_FOUND");  // only / serves the page
    ExpectError(client_->Delete("/v1/measurements/last"), 405, "METHOD_NOT_ALLOWED");
    ExpectError(client_->Post("/v1/calibrate", "{\"reference_m\": [0.4, 0.3]}", "application/json"),
                400, "BAD_REQUEST");
    ExpectError(
        client_->Post("/v1/calibrate", "{\"reference_m\": [0.4, -0.3, 0.2]}", "application/json"),
        400, "BAD_REQUEST");
    ExpectError(client_->Post("/v1/calibrate", "", "application/json"), 400, "BAD_REQUEST");
    const std::string big(256 * 1024, 'x');
    ExpectError(client_->Post("/v1/measure", big, "application/json"), 413, "PAYLOAD_TOO_LARGE");
    EXPECT_FALSE(service_->Busy());  // none of them started a measurement

    auto health = client_->Get("/v1/health");
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
    auto ok = client_->Post("/v1/measure?wait=1", "{}", "application/json");
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->status, 200);
}

TEST_F(HttpApiTest, ParcelIdIsKeptWithTheMeasurementAndFindsIt) {
    auto with = client_->Post("/v1/measure?wait=1", R"({"parcel_id": "PKG 0042/a"})",
                              "application/json");
    ASSERT_TRUE(with);
    ASSERT_EQ(with->status, 200) << with->body;
    const json first = Body(with);
    EXPECT_EQ(first["parcel_id"], "PKG 0042/a");
    auto without = client_->Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(without);
    ASSERT_EQ(without->status, 200) << without->body;
    EXPECT_TRUE(Body(without)["parcel_id"].is_null());
    auto again = client_->Post("/v1/measure?wait=1", R"({"parcel_id": "PKG 0042/a"})",
                               "application/json");
    ASSERT_TRUE(again);
    ASSERT_EQ(again->status, 200) << again->body;

    // Newest first, that parcel's only; the query's value is URL-decoded like any other.
    auto found = client_->Get("/v1/measurements?parcel_id=PKG%200042%2Fa");
    ASSERT_TRUE(found);
    ASSERT_EQ(found->status, 200) << found->body;
    const json list = Body(found)["measurements"];
    ASSERT_EQ(list.size(), 2u) << list.dump();
    EXPECT_EQ(list[0], Body(again));
    EXPECT_EQ(list[1], first);
    auto one = client_->Get("/v1/measurements?parcel_id=PKG%200042%2Fa&limit=1");
    ASSERT_TRUE(one);
    EXPECT_EQ(Body(one)["measurements"].size(), 1u);
    auto none = client_->Get("/v1/measurements?parcel_id=PKG-9999");
    ASSERT_TRUE(none);
    EXPECT_EQ(none->status, 200);
    EXPECT_TRUE(Body(none)["measurements"].empty());
}

TEST_F(HttpApiTest, BadParcelIdsAre400NamingTheFieldAndStartNothing) {
    for (const std::string& body : std::vector<std::string>{
             R"({"parcel_id": ""})", R"({"parcel_id": 42})", R"({"parcel_id": null})",
          R"({"parcel_id": "tab\there"})", R"({"parcel_id": "caf\u00e9"})",
          R"({"parcel_id": ")" + std::string(65, 'x') + R"("})"}) {
        auto res = client_->Post("/v1/measure?wait=1", body, "application/json");
        ExpectError(res, 400, "BAD_REQUEST");
        EXPECT_NE(res->body.find("parcel_id"), std::string::npos) << res->body;
    }
    ExpectError(client_->Get("/v1/measurements?parcel_id="), 400, "BAD_REQUEST");
    auto list = client_->Get("/v1/measurements");
    ASSERT_TRUE(list);
    EXPECT_TRUE(Body(list)["measurements"].empty()) << list->body;
    auto longest = client_->Post("/v1/measure?wait=1",
                                 R"({"parcel_id": ")" + std::string(64, '~') + R"("})",
                                 "application/json");
    ASSERT_TRUE(longest);
    EXPECT_EQ(longest->status, 200) << longest->body;
}

TEST_F(HttpApiTest, CalibrateRunsTheStationCalibrationAndReportsRefusals) {
    auto done =
        client_->Post("/v1/calibrate", R"({"reference_m": [0.4, 0.3, 0.2]})", "application/json");
    ASSERT_TRUE(done);
    ASSERT_EQ(done->status, 200) << done->body;
    EXPECT_DOUBLE_EQ(Body(done)["reference_m"][2].get<double>(), 0.2);
    ExpectError(
        client_->Post("/v1/calibrate", R"({"reference_m": [0.4, 0.3, 1.5]})", "application/json"),
        422, "WRONG_REFERENCE");
    EXPECT_EQ(Body(client_->Get("/v1/status"))["last_error"]["code"], "WRONG_REFERENCE");
    auto calibration = client_->Get("/v1/calibration");
    ASSERT_TRUE(calibration);
    EXPECT_EQ(calibration->status, 200);
    EXPECT_EQ(Body(calibration)["calibrated"], true);
}

TEST_F(HttpApiTest, WhileCalibratingTheStateSaysSoAndMeasurementsAreRefused) {
    station_->hold = true;
    std::thread calibrate([this] {
        httplib::Client c("127.0.0.1", api_->tcp_port());
        c.set_read_timeout(20, 0);
        auto res =
            c.Post("/v1/calibrate", R"({"reference_m": [0.4, 0.3, 0.2]})", "application/json");
        EXPECT_TRUE(res && res->status == 200);
    });
    for (int i = 0; i < 1000 && !station_->in_capture; ++i) std::this_thread::sleep_for(2ms);
    const json s = Body(client_->Get("/v1/status"));
    EXPECT_EQ(s["state"], "calibrating");
    EXPECT_EQ(s["progress"]["pose"], 2);
    ExpectError(client_->Post("/v1/measure", "", "application/json"), 409, "BUSY");
    ExpectError(
        client_->Post("/v1/calibrate", R"({"reference_m": [0.4, 0.3, 0.2]})", "application/json"),
        409, "BUSY");
    station_->hold = false;
    calibrate.join();
    EXPECT_EQ(Body(client_->Get("/v1/status"))["state"], "idle");
}

// A device fault: the devices are re-opened at once in the background. While that fails the
// state is `error`; the next measurement tries them again and, once they answer, measures.
TEST_F(HttpApiTest, DeviceFailureIsStoredAndShownAsErrorState) {
    station_->fail_next = true;
    station_->fail_open = true;
    auto res = client_->Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 500) << res->body;  // a device failure, stored: the body says which
    EXPECT_EQ(Body(res)["status"], "failed");
    EXPECT_EQ(res->get_header_value("Location"), "/v1/measurements/" + Body(res)["id"].get<std::string>());
    EXPECT_EQ(Body(res)["reason"]["code"], "TURNTABLE_ERROR");
    const json s = SettledStatus();
    EXPECT_EQ(s["state"], "error");
    EXPECT_EQ(s["last_error"]["code"], "TURNTABLE_ERROR");
    EXPECT_EQ(s["last_error"]["message"], "sim: no answer");  // the re-open's own error
    station_->fail_open = false;
    auto again = client_->Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(again);
    EXPECT_EQ(Body(again)["status"], "ok");
    EXPECT_EQ(SettledStatus()["state"], "idle");
}

// A fault that re-opening cures (a drive that stalled once): idle again without a measurement,
// the fault still the last error.
TEST_F(HttpApiTest, DeviceFaultIsReOpenedInTheBackground) {
    station_->fail_next = true;
    ASSERT_EQ(Body(client_->Post("/v1/measure?wait=1", "", "application/json"))["status"],
              "failed");
    const json s = SettledStatus();
    EXPECT_EQ(s["state"], "idle");
    EXPECT_EQ(s["last_error"]["code"], "TURNTABLE_ERROR");
    EXPECT_TRUE(s["devices"]["turntable"]["ok"].get<bool>());
}

TEST_F(HttpApiTest, MetricsCountWhatFinishedByStatusReasonAndFault) {
    auto before = client_->Get("/metrics");
    ASSERT_TRUE(before);
    ASSERT_EQ(before->status, 200);
    EXPECT_EQ(before->get_header_value("Content-Type").rfind("text/plain; version=0.0.4", 0), 0u);
    EXPECT_EQ(test::ParsePrometheus(before->body).at("boxd_measurements_total{status=\"ok\"}"), 0);

    ASSERT_EQ(Body(client_->Post("/v1/measure?wait=1", "", "application/json"))["status"], "ok");
    station_->refuse_next = true;
    ASSERT_EQ(Body(client_->Post("/v1/measure?wait=1", "", "application/json"))["status"],
              "no_dim");
    station_->fail_next = true;
    station_->fail_open = true;  // and the re-open fails too: a second fault
    ASSERT_EQ(Body(client_->Post("/v1/measure?wait=1", "", "application/json"))["status"],
              "failed");
    ASSERT_EQ(SettledStatus()["state"], "error");

    auto after = client_->Get("/metrics");
    ASSERT_TRUE(after);
    const auto s = test::ParsePrometheus(after->body);
    EXPECT_EQ(s.at("boxd_measurements_total{status=\"ok\"}"), 1);
    EXPECT_EQ(s.at("boxd_measurements_total{status=\"no_dim\"}"), 1);
    EXPECT_EQ(s.at("boxd_measurements_total{status=\"failed\"}"), 1);
    EXPECT_EQ(
        s.at("boxd_measurement_reasons_total{status=\"no_dim\",code=\"MULTIPLE_OBJECTS\"}"), 1);
    EXPECT_EQ(s.at("boxd_device_faults_total{device=\"turntable\"}"), 2);
    EXPECT_EQ(s.at("boxd_measurement_cycle_seconds_count"), 3);
    // The failed run stopped before processing: two processing times, both 80 ms.
    EXPECT_EQ(s.at("boxd_measurement_processing_seconds_bucket{le=\"0.1\"}"), 2);
    EXPECT_EQ(s.at("boxd_state{state=\"error\"}"), 1);  // the turntable fault is the last word
    EXPECT_EQ(s.at("boxd_calibrated"), 1);
    EXPECT_EQ(s.at("boxd_calibration_age_seconds"), 42);
}

TEST_F(HttpApiTest, TheOperatorPageAndThreeJsAreServedFromDisk) {
    auto page = client_->Get("/");
    ASSERT_TRUE(page);
    ASSERT_EQ(page->status, 200) << page->body;
    EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
    EXPECT_NE(page->body.find(R"(<script src="/three.min.js">)"), std::string::npos);
    auto three = client_->Get("/three.min.js");
    ASSERT_TRUE(three);
    ASSERT_EQ(three->status, 200);
    EXPECT_GT(three->body.size(), 100000u);  // Debian's libjs-three, not a download
}

TEST_F(HttpApiTest, AMissingPageOrThreeJsIs404NamingTheKey) {
    api_.reset();
    ServerConfig config;
    config.listen = "127.0.0.1:0";
    config.web_dir = (dir_ / "no-web").string();
    config.three_js = (dir_ / "none.js").string();
    StartApi(config);
    ExpectError(client_->Get("/index.html"), 404, "NOT_FOUND");  // only / serves the page
    EXPECT_NE(client_->Get("/")->body.find("server.web_dir"), std::string::npos);
    ExpectError(client_->Get("/three.min.js"), 404, "NOT_FOUND");
    EXPECT_NE(client_->Get("/three.min.js")->body.find("server.three_js"), std::string::npos);
}

TEST_F(HttpApiTest, AbortStopsTheTableAndRecordsTheAbortedMeasurement) {
    station_->hold = true;
    auto first = client_->Post("/v1/measure", "", "application/json");
    ASSERT_TRUE(first);
    ASSERT_EQ(first->status, 202);
    for (int i = 0; i < 1000 && !station_->in_capture; ++i) std::this_thread::sleep_for(2ms);
    service_->Abort();
    service_->Join();
    EXPECT_EQ(station_->stop_requests, 1);
    auto m = client_->Get("/v1/measurements/m-000001");
    ASSERT_TRUE(m);
    ASSERT_EQ(m->status, 200);
    EXPECT_EQ(Body(m)["status"], "failed");
    EXPECT_EQ(Body(m)["reason"]["code"], "ABORTED");
    ExpectError(client_->Post("/v1/measure", "", "application/json"), 503, "SHUTTING_DOWN");
}

}  // namespace
}  // namespace boxd
