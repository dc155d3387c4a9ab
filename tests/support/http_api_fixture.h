#pragma once
// The REST API in-process over a real loopback socket, in front of a ScriptedStation whose every
// state (busy, finished, failed) a test reaches on demand: the fixture of the HTTP API's tests.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "daemon/service/http_api.h"
#include "daemon/service/measurement_service.h"
#include "daemon/service/measurement_store.h"
#include "tests/support/scripted_station.h"
#include "tests/support/temp_dir.h"

// After the project headers: <resolv.h> (through httplib) defines _res, a name Eigen uses.
#include <httplib.h>

namespace boxd::test {

class HttpApiTest : public ::testing::Test {
protected:
    void StartApi(ServerConfig config) {
        auto store = MeasurementStore::Open(dir_.path(), 50);
        ASSERT_TRUE(store) << store.error().message;
        store_ = std::move(*store);
        station_ = std::make_shared<ScriptedStation>();
        service_ = std::make_unique<MeasurementService>(*store_, station_, false);
        ASSERT_TRUE(service_->OpenStation());
        api_ = std::make_unique<HttpApi>(config, *service_, *store_, [] { return true; });
        ASSERT_TRUE(api_->Start());
        ASSERT_GT(api_->tcp_port(), 0);
        client_ = std::make_unique<httplib::Client>("127.0.0.1", api_->tcp_port());
        client_->set_read_timeout(20, 0);
    }
    void SetUp() override {
        ServerConfig config;
        config.listen = "127.0.0.1:0";
        StartApi(config);
    }
    void TearDown() override {
        if (station_) station_->hold = false;
        api_.reset();
        service_.reset();
    }

    static nlohmann::json Body(const httplib::Result& res) { return nlohmann::json::parse(res->body); }
    static void ExpectError(const httplib::Result& res, int status, const std::string& code) {
        ASSERT_TRUE(res) << httplib::to_string(res.error());
        EXPECT_EQ(res->status, status) << res->body;
        const nlohmann::json j = nlohmann::json::parse(res->body, nullptr, false);
        ASSERT_TRUE(j.is_object()) << res->body;
        EXPECT_EQ(j["error"]["code"], code) << res->body;
        EXPECT_TRUE(j["error"]["message"].is_string());
    }
    // Returns GET /v1/status once the devices are no longer coming up (a background open after
    // a fault has answered).
    nlohmann::json SettledStatus() {
        nlohmann::json s;
        for (int i = 0; i < 1000; ++i) {
            s = Body(client_->Get("/v1/status"));
            if (s["state"] != "starting") break;
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        return s;
    }
    void WaitUntilIdle() {
        for (int i = 0; i < 2000 && service_->Busy(); ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        ASSERT_FALSE(service_->Busy());
    }

    TempDir dir_;
    std::unique_ptr<MeasurementStore> store_;
    std::shared_ptr<ScriptedStation> station_;
    std::unique_ptr<MeasurementService> service_;
    std::unique_ptr<HttpApi> api_;
    std::unique_ptr<httplib::Client> client_;
};

}  // namespace boxd::test
