// What an integrator relies on beyond the bodies: the status code says what happened (a failed
// measurement is a 5xx, a refusal a 200 whose reason says why), a misspelt body key is a 400
// naming it (the barcode is never dropped in silence), a wrong method on a known path is a 405
// with Allow, and the last measurement's id survives a restart.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/support/http_api_fixture.h"

namespace boxd {
namespace {

using nlohmann::json;
using test::HttpApiTest;

TEST_F(HttpApiTest, AFailedMeasurementIs500WithTheStoredResultARefusalIs200) {
    station_->fail_next = true;
    auto failed = client_->Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(failed);
    EXPECT_EQ(failed->status, 500) << failed->body;
    const json body = Body(failed);
    EXPECT_EQ(body["status"], "failed");
    EXPECT_EQ(body["reason"]["code"], "TURNTABLE_ERROR");
    auto stored = client_->Get(failed->get_header_value("Location"));
    ASSERT_TRUE(stored);
    EXPECT_EQ(stored->status, 200);  // the stored record itself is found, as any other
    EXPECT_EQ(Body(stored), body);
    WaitUntilIdle();

    station_->refuse_next = true;
    auto refused = client_->Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, 200) << refused->body;
    EXPECT_EQ(Body(refused)["status"], "no_dim");
}

TEST_F(HttpApiTest, UnknownBodyKeysAre400NamingTheKeyAndStartNothing) {
    for (const std::string key : {"parcelId", "parcel", "Parcel_ID"}) {
        auto res =
            client_->Post("/v1/measure?wait=1", R"({")" + key + R"(": "ABC"})", "application/json");
        ExpectError(res, 400, "BAD_REQUEST");
        EXPECT_NE(res->body.find(key), std::string::npos) << res->body;
        EXPECT_NE(res->body.find("parcel_id"), std::string::npos) << res->body;  // what it may be
    }
    auto both =
        client_->Post("/v1/measure", R"({"parcel_id": "A", "wait": 1})", "application/json");
    ExpectError(both, 400, "BAD_REQUEST");
    EXPECT_NE(both->body.find("\\\"wait\\\""), std::string::npos) << both->body;
    auto calibrate =
        client_->Post("/v1/calibrate", R"({"reference_m": [0.4, 0.3, 0.2], "referenceM": 1})",
                      "application/json");
    ExpectError(calibrate, 400, "BAD_REQUEST");
    EXPECT_NE(calibrate->body.find("referenceM"), std::string::npos) << calibrate->body;
    auto list = client_->Get("/v1/measurements");
    ASSERT_TRUE(list);
    EXPECT_TRUE(Body(list)["measurements"].empty()) << list->body;
    EXPECT_EQ(Body(client_->Get("/v1/calibration"))["history"].size(), 0u);
}

TEST_F(HttpApiTest, AWrongMethodOnAKnownPathIs405WithAllow) {
    struct Case {
        httplib::Result res;
        std::string allow;
    };
    std::vector<Case> cases;
    cases.push_back({client_->Get("/v1/measure"), "POST"});
    cases.push_back({client_->Put("/v1/measure", "{}", "application/json"), "POST"});
    cases.push_back({client_->Post("/v1/measurements/last", "", "application/json"), "GET, HEAD"});
    cases.push_back({client_->Delete("/v1/measurements/m-000001/cloud.ply"), "GET, HEAD"});
    cases.push_back({client_->Get("/v1/calibrate"), "POST"});
    cases.push_back({client_->Post("/v1/status", "", "application/json"), "GET, HEAD"});
    for (const Case& c : cases) {
        ExpectError(c.res, 405, "METHOD_NOT_ALLOWED");
        EXPECT_EQ(c.res->get_header_value("Allow"), c.allow) << c.res->body;
    }
    ExpectError(client_->Post("/v1/nothing", "", "application/json"), 404, "NOT_FOUND");
    ExpectError(client_->Get("/v1/measurements/a/b/c"), 404, "NOT_FOUND");
    EXPECT_FALSE(service_->Busy());
}

TEST_F(HttpApiTest, TheLastMeasurementIdIsRestoredAfterARestart) {
    EXPECT_TRUE(Body(client_->Get("/v1/status"))["last_measurement_id"].is_null());
    ASSERT_EQ(client_->Post("/v1/measure?wait=1", "", "application/json")->status, 200);
    ASSERT_EQ(client_->Post("/v1/measure?wait=1", "", "application/json")->status, 200);
    EXPECT_EQ(Body(client_->Get("/v1/status"))["last_measurement_id"], "m-000002");

    // A new process: the store opened again from disk, a new service and API on it.
    api_.reset();
    service_.reset();
    store_.reset();
    ServerConfig config;
    config.listen = "127.0.0.1:0";
    StartApi(config);
    const json status = Body(client_->Get("/v1/status"));
    EXPECT_EQ(status["last_measurement_id"], "m-000002") << status.dump();
    EXPECT_EQ(Body(client_->Get("/v1/measurements/last"))["id"], "m-000002");
}

// The page's files carry an ETag: a browser revalidates them on each load, and one that did not
// change costs a 304 without a body (three.js alone is 850 KB).
TEST_F(HttpApiTest, ThePagesFilesAreRevalidatedByETag) {
    for (const char* path : {"/", "/page.js", "/page.css", "/cloud_view.js", "/three.min.js"}) {
        auto first = client_->Get(path);
        ASSERT_TRUE(first);
        ASSERT_EQ(first->status, 200) << path << ": " << first->body;
        EXPECT_EQ(first->get_header_value("Cache-Control"), "no-cache") << path;
        const std::string etag = first->get_header_value("ETag");
        ASSERT_FALSE(etag.empty()) << path;
        auto again = client_->Get(path, {{"If-None-Match", etag}});
        ASSERT_TRUE(again);
        EXPECT_EQ(again->status, 304) << path;
        EXPECT_TRUE(again->body.empty()) << path;
        EXPECT_EQ(again->get_header_value("ETag"), etag) << path;
        auto stale = client_->Get(path, {{"If-None-Match", "\"0-0\""}});
        ASSERT_TRUE(stale);
        EXPECT_EQ(stale->status, 200) << path;
        EXPECT_EQ(stale->body, first->body) << path;
    }
    EXPECT_NE(client_->Get("/")->body.find(R"(<script src="/page.js">)"), std::string::npos);
}

}  // namespace
}  // namespace boxd
