// The early-stop rule: when the poses so far surround the object, and when their measurement may
// end a capture (a flat-faced cuboid measured ok: its worst 95% bound) or not.
#include "pipeline/early_stop.h"

#include <gtest/gtest.h>

#include <cmath>

namespace boxd {
namespace {

TEST(WidestGapDeg, IsTheLargestTurnBetweenNeighbouringViews) {
    EXPECT_DOUBLE_EQ(WidestGapDeg({0.0}), 360.0);
    EXPECT_DOUBLE_EQ(WidestGapDeg({0.0, 180.0}), 180.0);
    EXPECT_DOUBLE_EQ(WidestGapDeg({0.0, 60.0, 120.0, 180.0, 240.0}), 120.0);  // 240 back to 360
    EXPECT_DOUBLE_EQ(WidestGapDeg({0.0, -60.0, -120.0, -180.0, -240.0, -300.0}), 60.0);
    EXPECT_DOUBLE_EQ(WidestGapDeg({350.0, 10.0, 370.0}), 340.0);  // 370 is 10 again
}

TEST(SurroundsObject, NoGapWiderThanAQuarterTurn) {
    EXPECT_FALSE(SurroundsObject({0.0, 60.0, 120.0, 180.0}));  // 180 back to 360
    EXPECT_TRUE(SurroundsObject({0.0, 90.0, 180.0, 270.0}));
    EXPECT_FALSE(SurroundsObject({0.0}));
}

MeasurementResult FlatCuboid() {
    MeasurementResult r;
    r.status = MeasurementStatus::kOk;
    r.shape = "cuboid";
    r.uncertainty_m = DimensionUncertainty{0.0011, 0.0019, 0.0007};
    r.quality.face_flatness = 1.2;
    return r;
}

TEST(DeterminingBound, IsTheWorstBoundOfAFlatFacedCuboid) {
    EXPECT_DOUBLE_EQ(DeterminingBound(FlatCuboid()), 0.0019);
}

TEST(DeterminingBound, NothingElseMayEndACapture) {
    MeasurementResult bulged = FlatCuboid();
    bulged.quality.face_flatness = 4.0;  // a 3 mm bulge the cells cannot place
    MeasurementResult unknown = FlatCuboid();
    unknown.quality.face_flatness.reset();
    MeasurementResult round = FlatCuboid();
    round.shape = "irregular";
    MeasurementResult refused = FlatCuboid();
    refused.status = MeasurementStatus::kNoDim;
    MeasurementResult unbounded = FlatCuboid();
    unbounded.uncertainty_m.reset();
    for (const MeasurementResult& r : {bulged, unknown, round, refused, unbounded}) {
        EXPECT_TRUE(std::isinf(DeterminingBound(r)));
    }
}

}  // namespace
}  // namespace boxd
