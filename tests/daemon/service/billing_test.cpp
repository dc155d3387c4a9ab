// Known answers of the billing arithmetic: divisions in millimetres and inches, values on and
// beside the rounding's boundaries, both rounding rules, the bound and the range that keep a
// dimension from being stated, and each carrier's dimensional and billable weight.
#include "daemon/service/billing.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "pipeline/io/measurement.h"

namespace boxd {
namespace {

constexpr double kInch = 0.0254;

BillingConfig Metric(BillingRounding rounding) {
    BillingConfig c;
    c.rounding = rounding;
    c.divisors = {{"express", 5000.0}, {"air", 6000.0}};
    return c;
}

struct Case {
    double value_m;
    double bound_m;
    BillingRounding rounding;
    bool stated;
    long divisions;
};

TEST(Bill, MetricLengthsInFiveMillimetreDivisions) {
    const Case cases[] = {
        {0.2000, 0.0010, BillingRounding::kNearest, true, 40},  // on a division
        {0.2000, 0.0010, BillingRounding::kUp, true, 40},       // on a division: not up
        {0.2024, 0.0010, BillingRounding::kNearest, true, 40},  // 40.48: down, moved 2.4 mm
        {0.2025, 0.0010, BillingRounding::kNearest, true, 41},  // 40.5: half up
        {0.2026, 0.0010, BillingRounding::kNearest, true, 41},
        {0.2001, 0.0001, BillingRounding::kUp, true, 41},       // any fraction up: 4.9 + 0.1 mm
        {0.2024, 0.0025, BillingRounding::kNearest, true, 40},  // 2.5 + 2.4 = 4.9 mm: within
        {0.2024, 0.0027, BillingRounding::kNearest, false, 0},  // 2.7 + 2.4 = 5.1 mm: beyond
        {0.2001, 0.0002, BillingRounding::kUp, false, 0},       // 0.2 + 4.9 = 5.1 mm: beyond
        {0.0300, 0.0001, BillingRounding::kNearest, false, 0},  // under the 50 mm range
        {1.3000, 0.0001, BillingRounding::kNearest, false, 0},  // over the 1.2 m range
    };
    for (const Case& c : cases) {
        const Billing b = Bill({c.value_m, 0.3, 0.2}, {c.bound_m, 0.001, 0.001}, std::nullopt,
                               Metric(c.rounding));
        const BilledDimension& d = b.dimensions[0];
        EXPECT_EQ(d.stated, c.stated) << c.value_m << " +- " << c.bound_m;
        EXPECT_EQ(b.billable, c.stated) << c.value_m;
        if (c.stated) {
            EXPECT_EQ(d.divisions, c.divisions) << c.value_m;
            EXPECT_DOUBLE_EQ(d.value, 5.0 * static_cast<double>(c.divisions));
        } else {
            EXPECT_NE(d.why_not.find("length"), std::string::npos) << d.why_not;
            EXPECT_EQ(b.reason, d.why_not);
            EXPECT_TRUE(b.carriers.empty());
        }
    }
}

TEST(Bill, TheReasonNamesTheBoundOrTheRange) {
    Billing b = Bill({0.4, 0.3, 0.2}, {0.001, 0.009, 0.001}, std::nullopt,
                     Metric(BillingRounding::kNearest));
    EXPECT_FALSE(b.billable);
    EXPECT_TRUE(b.dimensions[0].stated);
    EXPECT_FALSE(b.dimensions[1].stated);
    EXPECT_NE(b.reason.find("width: its bound 9.00 mm"), std::string::npos) << b.reason;
    b = Bill({0.4, 0.3, 0.02}, {0.001, 0.001, 0.001}, std::nullopt,
             Metric(BillingRounding::kNearest));
    EXPECT_NE(b.reason.find("height 20.0 mm is outside the measuring range 50.0-1200.0 mm"),
              std::string::npos)
        << b.reason;
}

TEST(Bill, DimensionalWeightsPerCarrierRoundUpToTheirDivision) {
    // 400 x 300 x 200 mm: 24,000 cm³; / 5000 = 4.8 kg exactly, / 6000 = 4.0 kg exactly.
    Billing b = Bill({0.4, 0.3, 0.2}, {0.001, 0.001, 0.001}, std::nullopt,
                     Metric(BillingRounding::kNearest));
    ASSERT_TRUE(b.billable) << b.reason;
    EXPECT_NEAR(b.volume, 24000.0, 1e-6);
    ASSERT_EQ(b.carriers.size(), 2u);
    EXPECT_EQ(b.carriers[0].carrier, "express");
    EXPECT_NEAR(b.carriers[0].dimensional_weight, 4.8, 1e-9);
    EXPECT_NEAR(b.carriers[1].dimensional_weight, 4.0, 1e-9);
    EXPECT_FALSE(b.carriers[0].billable_weight.has_value());  // not weighed
    // 405 x 300 x 200 mm: 24,300 cm³ -> 4.86 kg, up to 4.9; 4.05 kg, up to 4.1.
    b = Bill({0.405, 0.3, 0.2}, {0.001, 0.001, 0.001}, 4.87, Metric(BillingRounding::kNearest));
    ASSERT_TRUE(b.billable) << b.reason;
    EXPECT_NEAR(b.carriers[0].dimensional_weight, 4.9, 1e-9);
    EXPECT_NEAR(b.carriers[1].dimensional_weight, 4.1, 1e-9);
    // The billable weight is the larger of the actual and the dimensional, each rounded up to
    // the weight division: 4.87 kg bills as 4.9.
    EXPECT_NEAR(*b.carriers[0].billable_weight, 4.9, 1e-9);
    EXPECT_NEAR(*b.carriers[1].billable_weight, 4.9, 1e-9);
    b = Bill({0.405, 0.3, 0.2}, {0.001, 0.001, 0.001}, 4.8, Metric(BillingRounding::kNearest));
    EXPECT_NEAR(*b.carriers[1].billable_weight, 4.8, 1e-9);  // on the division: unchanged
}

TEST(Bill, TheScalesWeightComesInTheBillingsUnits) {
    Weighing w;
    w.value = 2.5;
    w.unit = "kg";
    EXPECT_NEAR(*ActualWeight(w, BillingUnits::kMetric), 2.5, 1e-12);
    EXPECT_NEAR(*ActualWeight(w, BillingUnits::kImperial), 5.51155655, 1e-8);
    w.unit = "lb";
    EXPECT_NEAR(*ActualWeight(w, BillingUnits::kMetric), 1.133980925, 1e-9);
    EXPECT_NEAR(*ActualWeight(w, BillingUnits::kImperial), 2.5, 1e-12);
    // Below the scale's minimum load no weight is stated, and none is billed.
    w.value.reset();
    w.why_not = "0.06 kg is below the scale's minimum load of 0.1 kg";
    EXPECT_FALSE(ActualWeight(w, BillingUnits::kMetric).has_value());
    EXPECT_FALSE(ActualWeight(std::nullopt, BillingUnits::kMetric).has_value());
}

TEST(Bill, ImperialInFifthsOfAnInchAndPoundsPerCubicInch) {
    BillingConfig c;
    c.units = BillingUnits::kImperial;
    c.division_m = {0.2 * kInch, 0.2 * kInch, 0.2 * kInch};
    c.weight_division = 1.0;  // whole pounds
    c.divisors = {{"domestic", 139.0}};
    // 12.0 x 10.1 x 7.95 in: 60, 50.5 -> 51 (10.2 in), 39.75 -> 40 (8.0 in).
    const Billing b =
        Bill({12.0 * kInch, 10.1 * kInch, 7.95 * kInch}, {0.002, 0.002, 0.002}, std::nullopt, c);
    ASSERT_TRUE(b.billable) << b.reason;
    EXPECT_EQ(b.dimensions[0].divisions, 60);
    EXPECT_EQ(b.dimensions[1].divisions, 51);
    EXPECT_EQ(b.dimensions[2].divisions, 40);
    EXPECT_NEAR(b.dimensions[1].value, 10.2, 1e-9);
    // 12 x 10.2 x 8 = 979.2 in³ / 139 = 7.04 lb: up to 8 lb.
    EXPECT_NEAR(b.volume, 979.2, 1e-6);
    EXPECT_NEAR(b.carriers[0].dimensional_weight, 8.0, 1e-9);
    EXPECT_STREQ(LengthUnit(b.units), "in");
    EXPECT_STREQ(VolumeUnit(b.units), "in3");
    EXPECT_STREQ(WeightUnit(b.units), "lb");
}

TEST(Bill, TheResultCarriesTheBlock) {
    MeasurementResult r;
    r.status = MeasurementStatus::kOk;
    EXPECT_FALSE(ToJson(r).contains("billing"));
    r.billing =
        Bill({0.4, 0.3, 0.2024}, {0.001, 0.009, 0.001}, 3.2, Metric(BillingRounding::kNearest));
    const nlohmann::json j = ToJson(r)["billing"];
    EXPECT_EQ(j["billable"], false);
    EXPECT_EQ(j["units"]["length"], "mm");
    EXPECT_EQ(j["rounding"], "nearest");
    EXPECT_EQ(j["length"]["divisions"], 80);
    EXPECT_EQ(j["length"]["value"], 400.0);
    EXPECT_TRUE(j["width"]["divisions"].is_null());
    EXPECT_NE(j["width"]["why_not"].get<std::string>().find("width"), std::string::npos);
    EXPECT_EQ(j["height"]["value"], 200.0);
    EXPECT_EQ(j["reason"], j["width"]["why_not"]);
    EXPECT_TRUE(j["volume"].is_null());
    EXPECT_EQ(j["actual_weight"], 3.2);
    EXPECT_TRUE(j["carriers"].empty());
    r.billing = Bill({0.4, 0.3, 0.2}, {0.001, 0.001, 0.001}, 3.2, Metric(BillingRounding::kUp));
    const nlohmann::json k = ToJson(r)["billing"];
    EXPECT_EQ(k["billable"], true);
    EXPECT_TRUE(k["reason"].is_null());
    EXPECT_EQ(k["volume"], 24000.0);
    ASSERT_EQ(k["carriers"].size(), 2u);
    EXPECT_EQ(k["carriers"][1]["carrier"], "air");
    EXPECT_EQ(k["carriers"][1]["divisor"], 6000.0);
    EXPECT_EQ(k["carriers"][0]["billable_weight"], 4.8);
    EXPECT_EQ(k["carriers"][1]["billable_weight"], 4.0);
}

TEST(BillingConfig, ValidateNamesTheKey) {
    EXPECT_TRUE(BillingConfig{}.Validate());
    BillingConfig c;
    c.division_m[2] = 0.0;
    EXPECT_NE(c.Validate().error().message.find("billing.division"), std::string::npos);
    c = BillingConfig{};
    c.min_dimension_m = 2.0;
    EXPECT_FALSE(c.Validate());
    c = BillingConfig{};
    c.divisors = {{"air", 6000.0}, {"air", 5000.0}};
    EXPECT_NE(c.Validate().error().message.find("billing.divisors.air: named twice"),
              std::string::npos);
    c.divisors = {{"air", -1.0}};
    EXPECT_FALSE(c.Validate());
    c.divisors.clear();
    EXPECT_FALSE(c.Validate());
    c = BillingConfig{};
    c.max_error_divisions = 0.0;
    EXPECT_FALSE(c.Validate());
}

}  // namespace
}  // namespace boxd
