// The CSV export: the writer on records made by hand (quoting, formulas defused, a column pair
// per carrier), the `since` forms, and the export through the real HTTP API and `boxd export`.
#include "daemon/service/measurement_csv.h"

#include <gtest/gtest.h>

#include <sstream>

#include "tests/support/http_api_fixture.h"
#include "tests/support/run_command.h"

namespace boxd {
namespace {

using nlohmann::json;

std::vector<std::string> Lines(const std::string& csv) {
    std::vector<std::string> out;
    std::size_t at = 0;
    while (at < csv.size()) {
        const std::size_t end = csv.find("\r\n", at);
        out.push_back(csv.substr(at, end - at));
        at = end == std::string::npos ? csv.size() : end + 2;
    }
    return out;
}

json Billed(const std::string& carrier, double dimensional, double billable) {
    return {{"billable", true},
            {"units", {{"length", "mm"}, {"volume", "cm3"}, {"weight", "kg"}}},
            {"length", {{"value", 400.0}}},
            {"width", {{"value", 300.0}}},
            {"height", {{"value", 200.0}}},
            {"volume", 24000.0},
            {"actual_weight", 2.5},
            {"carriers",
             {{{"carrier", carrier},
               {"dimensional_weight", dimensional},
               {"billable_weight", billable}}}}};
}

TEST(MeasurementsCsv, OneRowPerRecordWithEveryCarriersColumns) {
    json a = {{"id", "m-000001"},
              {"finished_at", "2026-12-05T10:00:00.000Z"},
              {"parcel_id", "PKG, \"7\""},
              {"status", "ok"},
              {"dimensions", {{"length_m", 0.40012}, {"width_m", 0.3}, {"height_m", 0.2}}},
              {"uncertainty_m", {{"length_m", 0.0011}, {"width_m", 0.001}, {"height_m", 0.001}}},
              {"shape", "cuboid"},
              {"weight", {{"value", 2.5}, {"unit", "kg"}}},
              {"billing", Billed("express", 4.8, 4.8)}};
    json b = {{"id", "m-000002"},
              {"finished_at", "2026-12-05T10:01:00.000Z"},
              {"parcel_id", "=HYPERLINK(\"http://x\")"},
              {"status", "failed"},
              {"reason", {{"code", "SCALE_ERROR"}, {"message", "no reply"}}},
              {"dimensions", nullptr},
              {"billing", Billed("air", 4.0, 4.0)}};
    const auto lines = Lines(MeasurementsCsv({a, b}));
    ASSERT_EQ(lines.size(), 3u);
    EXPECT_EQ(lines[0].rfind("id,finished_at,parcel_id,status,reason_code,reason,length_mm,", 0),
              0u);
    EXPECT_NE(lines[0].find(",express_dimensional_weight,express_billable_weight,"
                            "air_dimensional_weight,air_billable_weight"),
              std::string::npos)
        << lines[0];
    // Quoted with its quotes doubled; mm to the hundredth; the other carrier's columns empty.
    EXPECT_EQ(lines[1].rfind("m-000001,2026-12-05T10:00:00.000Z,\"PKG, \"\"7\"\"\",ok,,,400.12,"
                             "300.00,200.00,1.10,1.00,1.00,cuboid,2.5000,kg,true,",
                             0),
              0u)
        << lines[1];
    EXPECT_NE(lines[1].find(",4.8000,4.8000,,"), std::string::npos) << lines[1];
    // A formula in a parcel id is text; a failed record has no dimensions.
    EXPECT_EQ(lines[2].rfind("m-000002,2026-12-05T10:01:00.000Z,\"'=HYPERLINK(\"\"http://x\"\")\","
                             "failed,SCALE_ERROR,no reply,,,,",
                             0),
              0u)
        << lines[2];
    EXPECT_NE(lines[2].find(",,,4.0000,4.0000"), std::string::npos) << lines[2];
}

TEST(MeasurementsCsv, SinceTakesADateOrATime) {
    for (const char* ok :
         {"2026-12-05", "2026-12-05T10:00", "2026-12-05T10:00:00", "2026-12-05T10:00:00Z",
          "2026-12-05T10:00:00.5Z", "2026-12-05T10:00:00.000Z"}) {
        auto since = CheckSince(ok);
        ASSERT_TRUE(since) << ok;
        EXPECT_EQ(since->back() == 'Z', false) << ok;  // compared without its Z
    }
    for (const char* bad : {"yesterday", "2026-12", "2026-12-05T10", "2026-12-05 10:00",
                            "2026-12-05T10:00:00.", "2026-12-05T10:00:00.0000Z", ""}) {
        auto since = CheckSince(bad);
        ASSERT_FALSE(since) << bad;
        EXPECT_EQ(since.error().code, ErrorCode::kInvalidInput);
    }
}

using test::HttpApiTest;

TEST_F(HttpApiTest, MeasurementsAreExportedAsCsvOverHttpAndByTheCommandLine) {
    for (const char* parcel : {R"({"parcel_id": "PKG-1"})", R"({"parcel_id": "PKG-2"})"}) {
        auto res = client_->Post("/v1/measure?wait=1", parcel, "application/json");
        ASSERT_TRUE(res);
        ASSERT_EQ(res->status, 200) << res->body;
    }
    auto csv = client_->Get("/v1/measurements.csv");
    ASSERT_TRUE(csv);
    ASSERT_EQ(csv->status, 200) << csv->body;
    EXPECT_EQ(csv->get_header_value("Content-Type").rfind("text/csv", 0), 0u);
    const auto lines = Lines(csv->body);
    ASSERT_EQ(lines.size(), 3u) << csv->body;
    EXPECT_NE(lines[1].find(",PKG-1,ok,"), std::string::npos) << lines[1];
    EXPECT_NE(lines[2].find(",PKG-2,ok,"), std::string::npos) << lines[2];
    EXPECT_NE(lines[0].find("express_billable_weight"), std::string::npos);

    auto later = client_->Get("/v1/measurements.csv?since=2999-01-01");
    ASSERT_TRUE(later);
    EXPECT_EQ(Lines(later->body).size(), 1u) << later->body;  // the header alone
    ExpectError(client_->Get("/v1/measurements.csv?since=yesterday"), 400, "BAD_REQUEST");

    const auto exported = test::RunBoxd({"export", "--data-dir", dir_.path().string()});
    EXPECT_EQ(exported.exit_code, 0) << exported.err;
    EXPECT_EQ(exported.out, csv->body);
    const auto bad =
        test::RunBoxd({"export", "--data-dir", dir_.path().string(), "--since", "last week"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("--since must be a UTC date"), std::string::npos) << bad.err;
    const auto none = test::RunBoxd({"export", "--data-dir", (dir_.path() / "x").string()});
    EXPECT_EQ(none.exit_code, 2) << none.err;
}

}  // namespace
}  // namespace boxd
