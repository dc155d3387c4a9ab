// The station with its scale, through the real daemon: `boxd serve` on the simulated station
// (config/sim.yaml: the simulated indicator served over Modbus TCP on loopback), a parcel of
// known size and mass billed exactly as the tariff table says, and each of the indicator's
// faults a stored SCALE_ERROR before the table has turned at all.
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// config/sim.yaml with the simulated parcel's mass and the indicator's fault replaced.
fs::path SimConfigWith(const fs::path& dir, double load, const std::string& fault) {
    YAML::Node root = YAML::LoadFile(test::SimConfigPath().string());
    root["scale"]["simulated"]["load"] = load;
    root["scale"]["simulated"]["fault"] = fault;
    root["scale"]["timeout_ms"] = 2000;
    YAML::Emitter out;
    out << root;
    const fs::path path = dir / ("sim-" + fault + ".yaml");
    std::ofstream(path) << out.c_str() << "\n";
    return path;
}

// The move commands the simulated drive has received (its special register 105), read over
// Modbus TCP on the port its description names.
int DriveMoves(const std::string& description) {
    std::smatch m;
    if (!std::regex_search(description, m, std::regex(R"(127\.0\.0\.1:(\d+))"))) return -1;
    modbus_t* ctx = modbus_new_tcp("127.0.0.1", std::stoi(m[1]));
    uint16_t moves = 0;
    int got = -1;
    if (ctx && modbus_connect(ctx) == 0 && modbus_read_registers(ctx, 105, 1, &moves) == 1) {
        got = moves;
    }
    if (ctx) {
        modbus_close(ctx);
        modbus_free(ctx);
    }
    return got;
}

// The tariff table's answer for a 455 x 330 x 460 mm parcel in 5 mm divisions: 91 x 66 x 92
// divisions, 69,069 cm³; express (5000 cm³/kg) 13.8138 kg up to 13.9, air (6000) 11.5115 up to
// 11.6; each billable weight the larger of that and the actual weight rounded up to 0.1 kg.
TEST(ServeScale, BillsTheSimulatedParcelByItsSizeAndItsWeight) {
    const struct {
        double load_kg;
        double express_kg;
        double air_kg;
    } table[] = {{7.25, 13.9, 11.6}, {12.0, 13.9, 12.0}, {21.335, 21.4, 21.4}};
    for (const auto& row : table) {
        SCOPED_TRACE(row.load_kg);
        test::TempDir dir;
        test::ServeDaemon daemon(SimConfigWith(dir.path(), row.load_kg, "none"),
                                 dir.path() / "data", dir.path() / "boxd.log");
        ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir.path() / "boxd.log");
        auto res = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
        ASSERT_TRUE(res);
        ASSERT_EQ(res->status, 200) << res->body;
        const json j = json::parse(res->body);
        ASSERT_EQ(j["status"], "ok") << j.dump();
        EXPECT_DOUBLE_EQ(j["weight"]["value"].get<double>(), row.load_kg);
        EXPECT_EQ(j["weight"]["unit"], "kg");
        EXPECT_DOUBLE_EQ(j["weight"]["division"].get<double>(), 0.005);
        const json& b = j["billing"];
        ASSERT_TRUE(b["billable"].get<bool>()) << b.dump();
        EXPECT_EQ(b["length"]["divisions"], 91);
        EXPECT_EQ(b["width"]["divisions"], 66);
        EXPECT_EQ(b["height"]["divisions"], 92);
        EXPECT_DOUBLE_EQ(b["volume"].get<double>(), 69069.0);
        EXPECT_DOUBLE_EQ(b["actual_weight"].get<double>(), row.load_kg);
        ASSERT_EQ(b["carriers"].size(), 2u);
        EXPECT_EQ(b["carriers"][0]["carrier"], "express");
        EXPECT_NEAR(b["carriers"][0]["dimensional_weight"].get<double>(), 13.9, 1e-9);
        EXPECT_NEAR(b["carriers"][0]["billable_weight"].get<double>(), row.express_kg, 1e-9);
        EXPECT_NEAR(b["carriers"][1]["dimensional_weight"].get<double>(), 11.6, 1e-9);
        EXPECT_NEAR(b["carriers"][1]["billable_weight"].get<double>(), row.air_kg, 1e-9);
        // The stored record says the same.
        const json stored = daemon.GetJson("/v1/measurements/" + j["id"].get<std::string>());
        EXPECT_EQ(stored["weight"], j["weight"]);
        EXPECT_EQ(stored["billing"], j["billing"]);
    }
}

TEST(ServeScale, EachScaleFaultIsAStoredScaleErrorAndTheTableNeverTurns) {
    const struct {
        const char* fault;
        const char* says;
    } faults[] = {{"no_answer", "no reply"},
                  {"never_stable", "never settled"},
                  {"overload", "overload"},
                  {"drifting_zero", "drifting zero"}};
    for (const auto& f : faults) {
        SCOPED_TRACE(f.fault);
        test::TempDir dir;
        test::ServeDaemon daemon(SimConfigWith(dir.path(), 7.25, f.fault), dir.path() / "data",
                                 dir.path() / "boxd.log");
        ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir.path() / "boxd.log");
        auto res = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
        ASSERT_TRUE(res);
        EXPECT_EQ(res->status, 500) << res->body;
        const json j = json::parse(res->body);
        EXPECT_EQ(j["status"], "failed");
        EXPECT_EQ(j["reason"]["code"], "SCALE_ERROR");
        EXPECT_NE(j["reason"]["message"].get<std::string>().find(f.says), std::string::npos)
            << j["reason"]["message"];
        EXPECT_TRUE(j["dimensions"].is_null()) << j.dump();
        // Stored, and the station says which device failed.
        const json stored = daemon.GetJson("/v1/measurements/" + j["id"].get<std::string>());
        EXPECT_EQ(stored["reason"], j["reason"]);
        const json status = daemon.GetJson("/v1/status");
        EXPECT_EQ(status["devices"]["scale"]["ok"], false) << status.dump();
        EXPECT_EQ(status["devices"]["turntable"]["ok"], true);
        EXPECT_EQ(status["last_error"]["code"], "SCALE_ERROR");
        // The table was homed at start and has not been sent a single move.
        EXPECT_EQ(DriveMoves(status["devices"]["turntable"]["description"].get<std::string>()), 0);
    }
}

TEST(ServeScale, ZeroAndTareAreSentBetweenRuns) {
    test::TempDir dir;
    test::ServeDaemon daemon(SimConfigWith(dir.path(), 3.5, "none"), dir.path() / "data",
                             dir.path() / "boxd.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir.path() / "boxd.log");
    const auto measure = [&daemon] {
        auto res = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
        return res && res->status == 200 ? json::parse(res->body) : json();
    };
    // A tare leaves the gross weight (what the station reads) as it was.
    auto tared = daemon.client().Post("/v1/scale/tare", "", "application/json");
    ASSERT_TRUE(tared);
    ASSERT_EQ(tared->status, 200) << tared->body;
    EXPECT_EQ(json::parse(tared->body)["command"], "tare");
    EXPECT_DOUBLE_EQ(measure()["weight"]["value"].get<double>(), 3.5);
    // Zeroed with the parcel on it, the scale then reads about nothing: below Min, no weight
    // is stated and none is billed.
    auto zeroed = daemon.client().Post("/v1/scale/zero", "", "application/json");
    ASSERT_TRUE(zeroed);
    ASSERT_EQ(zeroed->status, 200) << zeroed->body;
    const json j = measure();
    ASSERT_EQ(j["status"], "ok") << j.dump();
    EXPECT_TRUE(j["weight"]["value"].is_null()) << j["weight"].dump();
    EXPECT_NE(j["weight"]["why_not"].get<std::string>().find("below the scale's minimum load"),
              std::string::npos);
    EXPECT_TRUE(j["billing"]["actual_weight"].is_null());
    EXPECT_TRUE(j["billing"]["carriers"][0]["billable_weight"].is_null());
    // A body is not a command's.
    auto odd = daemon.client().Post("/v1/scale/zero", R"({"now": true})", "application/json");
    ASSERT_TRUE(odd);
    EXPECT_EQ(odd->status, 400);
}

TEST(ServeScale, AStationWithoutAScaleSaysSo) {
    test::TempDir dir;
    YAML::Node root = YAML::LoadFile(test::SimConfigPath().string());
    root.remove("scale");
    YAML::Emitter out;
    out << root;
    std::ofstream(dir.path() / "noscale.yaml") << out.c_str() << "\n";
    test::ServeDaemon daemon(dir.path() / "noscale.yaml", dir.path() / "data",
                             dir.path() / "boxd.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir.path() / "boxd.log");
    EXPECT_TRUE(daemon.GetJson("/v1/status")["devices"]["scale"].is_null());
    auto res = daemon.client().Post("/v1/scale/zero", "", "application/json");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 404) << res->body;
    auto measured = daemon.client().Post("/v1/measure?wait=1", "", "application/json");
    ASSERT_TRUE(measured);
    const json j = json::parse(measured->body);
    EXPECT_FALSE(j.contains("weight"));
    EXPECT_TRUE(j["billing"]["actual_weight"].is_null());
}

}  // namespace
}  // namespace boxd
