// The operator page (GET /) in a real headless Chromium (Debian's chromium, software WebGL)
// against the real daemon on config/sim.yaml, driven over the DevTools protocol
// (tests/support/page_probe.py): at phone, tablet and desktop sizes nothing runs off the window
// (the full-page screenshot is exactly the window's width), the 3-D view fills its box and
// follows a resized window, and the history's size column is in view; while the next parcel is
// measured a live panel shows its poses and the result below is dimmed and labelled as the
// previous parcel's; a history row opens its measurement with its cloud; failed rows stand out;
// times are local and said to be.
#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/run_command.h"
#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using nlohmann::json;

// Runs the probe's steps on the page at `url`; returns one JSON object per step.
std::vector<json> Probe(const std::string& url, const test::TempDir& dir,
                        const std::vector<std::string>& steps) {
    std::vector<std::string> argv{"/usr/bin/python3",
                                  std::string(BOXD_SOURCE_DIR) + "/tests/support/page_probe.py",
                                  url, dir.path().string()};
    argv.insert(argv.end(), steps.begin(), steps.end());
    const auto out = test::RunCommand(argv);
    EXPECT_EQ(out.exit_code, 0) << out.err;
    std::vector<json> results;
    std::istringstream lines(out.out);
    for (std::string line; std::getline(lines, line);) results.push_back(json::parse(line));
    EXPECT_EQ(results.size(), steps.size()) << out.out << out.err;
    return results;
}

json MeasureOnce(test::ServeDaemon& daemon, const std::string& parcel) {
    auto res = daemon.client().Post("/v1/measure?wait=1", R"({"parcel_id": ")" + parcel + R"("})",
                                    "application/json");
    EXPECT_TRUE(res);
    if (!res) return json::object();
    EXPECT_EQ(res->status, 200) << res->body;
    return json::parse(res->body);
}

// Nothing wider than the window: the page does not scroll sideways, every section is inside it,
// the 3-D view fills its box, and the history's size column is in view.
void ExpectFits(const json& step) {
    SCOPED_TRACE(step["step"].get<std::string>());
    const json& p = step["page"];
    const double width = p["inner_width"].get<double>();
    EXPECT_LE(p["scroll_width"].get<double>(), width) << p.dump();
    EXPECT_EQ(step["screenshot"]["width"].get<double>(), width) << "the page runs off the window";
    for (const json& s : p["sections"]) {
        EXPECT_GE(s["left"].get<double>(), 0.0) << s.dump();
        EXPECT_LE(s["right"].get<double>(), width) << s.dump();
    }
    ASSERT_TRUE(p["canvas"].is_object()) << p.dump();
    EXPECT_NEAR(p["canvas"]["width"].get<double>(), p["view"]["width"].get<double>(), 1.0);
    EXPECT_NEAR(p["canvas"]["height"].get<double>(), p["view"]["height"].get<double>(), 1.0);
    EXPECT_GT(p["canvas"]["lit"].get<double>(), 500.0) << "the cloud did not reach the screen";
    ASSERT_TRUE(p["size_column"].is_object()) << p.dump();
    EXPECT_GT(p["size_column"]["width"].get<double>(), 40.0) << "the size column is hidden";
    EXPECT_LE(p["size_column"]["right"].get<double>(), width) << "the size column is off screen";
}

TEST(OperatorPage, FitsPhoneTabletAndDesktopAndShowsWhatIsMeasuredNow) {
    test::TempDir dir;
    test::ServeDaemon daemon(test::SimConfigPath(), dir / "data", dir / "serve.log");
    ASSERT_TRUE(daemon.WaitHealthy()) << test::ReadText(dir / "serve.log");
    const json first = MeasureOnce(daemon, "PKG-0815");
    const json second = MeasureOnce(daemon, "PKG-0816");
    ASSERT_EQ(first["status"], "ok") << first.dump();
    ASSERT_EQ(second["status"], "ok") << second.dump();

    const std::string url = "http://127.0.0.1:" + std::to_string(daemon.port()) + "/";
    const std::vector<json> steps =
        Probe(url, dir,
              {"360x740", "390x844", "768x1024", "1280x1000", "1920x1080", "resize:390x844",
               "measure", "open:m-000001"});
    ASSERT_EQ(steps.size(), 8u);
    for (std::size_t i = 0; i < 6; ++i) ExpectFits(steps[i]);

    const json& desktop = steps[3]["page"];
    EXPECT_EQ(desktop["last_id"], "m-000002");
    EXPECT_EQ(desktop["canvas"]["points"], second["quality"]["points"]);  // every fused point
    EXPECT_NE(desktop["history_text"].get<std::string>().find("PKG-0815"), std::string::npos);
    EXPECT_EQ(desktop["history_ids"], json({"m-000002", "m-000001"}));
    EXPECT_EQ(desktop["shown_rows"], json({"m-000002"}));
    EXPECT_EQ(desktop["failed_row_background"], "rgb(253, 232, 232)");  // failed rows stand out
    EXPECT_EQ(desktop["clock_note"].get<std::string>().rfind("times are local (UTC", 0), 0u);
    EXPECT_NE(desktop["last_note"].get<std::string>().find("finished "), std::string::npos);
    EXPECT_EQ(desktop["last_note"].get<std::string>().find("Z"), std::string::npos)
        << "a raw UTC timestamp: " << desktop["last_note"];
    // The calibration card: what a technician needs, not a path.
    EXPECT_NE(desktop["calibration"].get<std::string>().find("Made"), std::string::npos);
    EXPECT_EQ(desktop["calibration"].get<std::string>().find(".yaml"), std::string::npos);
    // config/sim.yaml bills: the result's block is on the page, each carrier by name.
    ASSERT_TRUE(second.contains("billing")) << second.dump();
    ASSERT_TRUE(desktop["billing"].is_string()) << "no billing table";
    const std::string billing = desktop["billing"].get<std::string>();
    EXPECT_NE(billing.find(second["billing"]["billable"].get<bool>() ? "billable" : "not billable"),
              std::string::npos)
        << billing;
    EXPECT_NE(billing.find("express"), std::string::npos) << billing;
    EXPECT_NE(billing.find("air"), std::string::npos) << billing;
    // Its scale weighed the parcel: the weight stands with the dimensions, and the billing
    // weighed it.
    ASSERT_TRUE(second.contains("weight")) << second.dump();
    const std::string weight = second["weight"]["value"].dump() + " kg";
    EXPECT_NE(desktop["dims"].get<std::string>().find("Weight" + weight), std::string::npos)
        << desktop["dims"];
    EXPECT_NE(billing.find("weighed" + weight), std::string::npos) << billing;
    // The metrology card: the event counter, the software, the stored records' check.
    const std::string audit = desktop["audit"].get<std::string>();
    EXPECT_NE(audit.find("Event counter0"), std::string::npos) << audit;
    EXPECT_NE(audit.find("SHA-256 "), std::string::npos) << audit;
    EXPECT_NE(audit.find("intact (checked at start)"), std::string::npos) << audit;

    // While the next parcel is measured: the live panel, the previous result dimmed and named.
    const json& measuring = steps[6];
    EXPECT_TRUE(measuring["live_seen"].get<bool>());
    const json& during = measuring["during"];
    ASSERT_TRUE(during["live"].is_object()) << during.dump();
    EXPECT_EQ(during["live"]["id"], "m-000003");
    EXPECT_TRUE(during["last_dimmed"].get<bool>());
    EXPECT_NE(during["previous_note"].get<std::string>().find("previous parcel (m-000002)"),
              std::string::npos)
        << during.dump();
    EXPECT_TRUE(measuring["finished"].get<bool>());
    EXPECT_EQ(measuring["page"]["last_id"], "m-000003");
    EXPECT_FALSE(measuring["page"]["last_dimmed"].get<bool>());
    EXPECT_TRUE(measuring["page"]["live"].is_null());

    // A history row opens that measurement with its cloud.
    const json& opened = steps[7];
    EXPECT_TRUE(opened["opened"].get<bool>());
    EXPECT_EQ(opened["page"]["last_id"], "m-000001");
    EXPECT_EQ(opened["page"]["last_label"], "Measurement");
    EXPECT_TRUE(opened["page"]["back_shown"].get<bool>());
    EXPECT_EQ(opened["page"]["canvas"]["points"], first["quality"]["points"]);
    EXPECT_EQ(opened["page"]["shown_rows"], json({"m-000001"}));
}

}  // namespace
}  // namespace boxd
