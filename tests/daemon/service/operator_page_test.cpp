// The operator page (GET /) in a real headless Chromium (Debian's chromium, software WebGL)
// against the real daemon on config/sim.yaml: after a measurement with a parcel id, the rendered
// page shows its id, the parcel, its length in mm and a <canvas> that drew the fused cloud.
#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "tests/support/run_command.h"
#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using nlohmann::json;

// Returns the DOM of `url` after Chromium ran its scripts (up to 20 s of page time).
std::string RenderedDom(const std::string& url) {
    const auto out = test::RunCommand(
        {"chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
         "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=1280,1000",
         "--virtual-time-budget=20000", "--dump-dom", url});
    EXPECT_EQ(out.exit_code, 0) << out.err;
    return out.out;
}

TEST(OperatorPage, ShowsTheLastMeasurementItsParcelItsLengthAndItsCloud) {
    test::TempDir dir;
    test::ServeDaemon daemon(test::SimConfigPath(), dir / "data", dir / "serve.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir / "serve.log");
    auto res = daemon.client().Post("/v1/measure?wait=1", R"({"parcel_id": "PKG-0815"})",
                                    "application/json");
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << res->body;
    const json m = json::parse(res->body);
    ASSERT_EQ(m["status"], "ok") << m.dump();

    const std::string dom = RenderedDom("http://127.0.0.1:" + std::to_string(daemon.port()) + "/");
    EXPECT_NE(dom.find(R"(id="last-id">m-000001<)"), std::string::npos) << dom;
    EXPECT_NE(dom.find("parcel PKG-0815"), std::string::npos) << dom;
    char length[32];
    std::snprintf(length, sizeof length, ">%.1f mm<", m["dimensions"]["length_m"].get<double>() * 1e3);
    EXPECT_NE(dom.find(length), std::string::npos) << length << " not in " << dom;
    // The history lists it too, with the parcel.
    EXPECT_NE(dom.find("<td>PKG-0815</td>"), std::string::npos) << dom;

    std::smatch canvas;
    ASSERT_TRUE(std::regex_search(
        dom, canvas, std::regex(R"re(<canvas[^>]*data-points="(\d+)"[^>]*data-lit-pixels="(\d+)")re")))
        << dom;
    EXPECT_EQ(std::stol(canvas[1]), m["quality"]["points"].get<long>());  // every fused point
    EXPECT_GT(std::stol(canvas[2]), 5000) << "the cloud did not reach the screen";
}

}  // namespace
}  // namespace boxd
