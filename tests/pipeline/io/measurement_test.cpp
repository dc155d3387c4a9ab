#include "pipeline/io/measurement.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace boxd {
namespace {

// A result with these dimensions (m) and 95% bounds (m).
nlohmann::json Written(double length, double bound) {
    MeasurementResult m;
    m.status = MeasurementStatus::kOk;
    MeasuredDimensions d;
    d.length_m = length;
    d.width_m = 0.3;
    d.height_m = 0.2;
    m.dimensions = d;
    m.shape = "cuboid";
    m.uncertainty_m = DimensionUncertainty{bound, bound, bound};
    return ToJson(m);
}

TEST(MeasurementJson, ValuesAreRoundedToTheHundredthOfAMillimetre) {
    const nlohmann::json j = Written(0.4000449, 0.0001);
    EXPECT_DOUBLE_EQ(j["dimensions"]["length_m"].get<double>(), 0.40004);
    EXPECT_DOUBLE_EQ(Written(0.4000451, 0.0001)["dimensions"]["length_m"].get<double>(), 0.40005);
}

TEST(MeasurementJson, BoundsHoldTheValuesOwnRoundingInQuadratureAndAreRoundedUp) {
    // The value written may be up to half a hundredth of a millimetre off what was measured,
    // uniformly: 1.96 / sqrt(12) of a hundredth at 95%, added in quadrature, then rounded up.
    const struct {
        double bound, written;
    } cases[] = {{0.0, 0.00001},       {0.000004, 0.00001}, {0.0000051, 0.00001},
                 {0.0000099, 0.00002}, {0.000123, 0.00013}, {0.0001251, 0.00013},
                 {0.0001299, 0.00014}, {0.00013, 0.00014},  {0.0021, 0.00211}};
    for (const auto& c : cases) {
        const nlohmann::json u = Written(0.4, c.bound)["uncertainty_m"];
        for (const char* key : {"length_m", "width_m", "height_m"}) {
            EXPECT_DOUBLE_EQ(u[key].get<double>(), c.written) << c.bound << " " << key;
            EXPECT_GE(u[key].get<double>(), c.bound) << "a bound is never written below itself";
        }
    }
}

}  // namespace
}  // namespace boxd
