// The refusal rules on hand-made stage outputs: each rule fires on its own condition with its
// code, and stays silent just inside its limit.
#include "pipeline/refusal.h"

#include <gtest/gtest.h>

#include <array>
#include <string>

namespace boxd {
namespace {

ObjectViews Views(int n, int points_each) {
    ObjectViews v;
    v.views.resize(static_cast<std::size_t>(n));
    for (auto& view : v.views) view.fusion_points.resize(static_cast<std::size_t>(points_each));
    v.fusion_points = static_cast<long>(n) * points_each;
    return v;
}

RegisteredViews Registered(int active, int rejected, double rmse_m) {
    RegisteredViews r;
    r.graph.active_edges = active;
    r.graph.rejected_edges = rejected;
    r.edges.attempted = active + rejected;
    r.edges.accepted = active + rejected;
    r.edges.mean_rmse_m = rmse_m;
    return r;
}

FusedFit Fit(double l, double w, double h, double face_sigma_m, long points) {
    FusedFit f;
    f.fused.points.resize(static_cast<std::size_t>(points));
    BoxFit box;
    box.length_m = l;
    box.width_m = w;
    box.height_m = h;
    box.face_sigma_m = face_sigma_m;
    f.box = box;
    return f;
}

TEST(CheckObjectViews, BorderOutsideAndEmptyViews) {
    const RefusalConfig refuse;
    ObjectViews v = Views(4, 200);
    EXPECT_FALSE(CheckObjectViews(v, refuse).has_value());

    v.views[2].border_points = refuse.max_border_points;  // at the limit: still whole
    EXPECT_FALSE(CheckObjectViews(v, refuse).has_value());
    v.views[2].border_points = refuse.max_border_points + 1;
    auto why = CheckObjectViews(v, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kObjectTooLarge);
    EXPECT_NE(why->message.find("pose 2"), std::string::npos) << why->message;

    v = Views(4, 200);
    v.views[1].outside_points = refuse.max_outside_points + 1;
    why = CheckObjectViews(v, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kObjectTooLarge);
    EXPECT_NE(why->message.find("measuring volume"), std::string::npos) << why->message;

    v = Views(4, (refuse.min_object_points - 1) / 4);
    why = CheckObjectViews(v, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kNoObject);
}

TEST(CheckRegisteredViews, MovedObjectUnregisteredViewsAndPoorAlignment) {
    const RefusalConfig refuse;
    EXPECT_FALSE(CheckRegisteredViews(Registered(36, 0, 0.001), 18, refuse).has_value());

    // A single view has nothing to register against: never judged.
    EXPECT_FALSE(CheckRegisteredViews(Registered(0, 0, 0.0), 1, refuse).has_value());

    RegisteredViews r = Registered(36, 0, 0.001);
    r.graph.max_model_yaw_deviation_rad = (refuse.max_model_yaw_deviation_deg + 0.5) * M_PI / 180;
    auto why = CheckRegisteredViews(r, 18, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kObjectMoved);

    r = Registered(36, 0, 0.001);
    r.graph.max_model_translation_deviation_m = refuse.max_model_translation_deviation_m * 1.1;
    EXPECT_EQ(CheckRegisteredViews(r, 18, refuse)->code, ErrorCode::kObjectMoved);

    // The alignments' centre of the table 8.8 mm and 7.1 sigmas from the calibration's: one of
    // the two is wrong.
    r = Registered(36, 0, 0.001);
    r.graph.centre_offset_m = 0.0088;
    r.graph.centre_disagreement = 7.1;
    why = CheckRegisteredViews(r, 18, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kRegistrationFailed);
    EXPECT_NE(why->message.find("8.8 mm"), std::string::npos) << why->message;
    r.graph.centre_disagreement = refuse.max_centre_disagreement_sigma * 0.9;
    EXPECT_FALSE(CheckRegisteredViews(r, 18, refuse).has_value());

    // 20% of 40 alignments rejected is the limit; 9 of 40 is past it.
    EXPECT_FALSE(CheckRegisteredViews(Registered(32, 8, 0.001), 18, refuse).has_value());
    EXPECT_EQ(CheckRegisteredViews(Registered(31, 9, 0.001), 18, refuse)->code,
              ErrorCode::kObjectMoved);

    // Five of 18 views (> 25%) left without an alignment although one tested each (a side in
    // common, or a top elsewhere): the alignments disagreed there.
    r = Registered(30, 0, 0.001);
    r.graph.unconstrained = {2, 5, 8, 11, 14};
    for (int k = 0; k < 18; ++k) r.edges.tested_views.push_back(k);
    EXPECT_EQ(CheckRegisteredViews(r, 18, refuse)->code, ErrorCode::kRegistrationFailed);
    // The same five sharing no surface with the views they were paired with (each saw sides the
    // others did not) rest on the turntable model: not refused.
    r.edges.tested_views = {0, 1, 3, 4, 6, 7, 9, 10, 12, 13, 15, 16, 17};
    EXPECT_FALSE(CheckRegisteredViews(r, 18, refuse).has_value());

    // Tried, none held, though they tested the views: refused.
    RegisteredViews none_aligned = Registered(0, 0, 0.0);
    none_aligned.edges.attempted = 30;
    for (int k = 0; k < 18; ++k) {
        none_aligned.graph.unconstrained.push_back(k);
        none_aligned.edges.tested_views.push_back(k);
    }
    auto failed = CheckRegisteredViews(none_aligned, 18, refuse);
    ASSERT_TRUE(failed.has_value());
    EXPECT_EQ(failed->code, ErrorCode::kRegistrationFailed);
    EXPECT_NE(failed->message.find("18 of 18 unregistered"), std::string::npos) << failed->message;
    // Views too far apart to share a surface (two or three poses) are not aligned at all, and
    // four views a quarter turn apart that each see other sides find none in common: either way
    // they rest on the turntable model and are not refused for it.
    EXPECT_FALSE(CheckRegisteredViews(Registered(0, 0, 0.0), 3, refuse).has_value());
    RegisteredViews apart = Registered(0, 0, 0.0);
    apart.edges.attempted = 4;
    apart.graph.unconstrained = {0, 1, 2, 3};
    EXPECT_FALSE(CheckRegisteredViews(apart, 4, refuse).has_value());

    why = CheckRegisteredViews(Registered(36, 0, refuse.max_registration_rmse_m * 1.5), 18, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kRegistrationFailed);
    EXPECT_NE(why->message.find("RMSE 6.0 mm"), std::string::npos) << why->message;
}

TEST(CheckFusedFit, ThinCloudFitErrorSmallObjectMovedViewAndRoughFaces) {
    const RefusalConfig refuse;
    EXPECT_FALSE(CheckFusedFit(Fit(0.4, 0.3, 0.2, 0.001, 5000), refuse).has_value());

    EXPECT_EQ(CheckFusedFit(Fit(0.4, 0.3, 0.2, 0.001, refuse.min_object_points - 1), refuse)->code,
              ErrorCode::kNoObject);

    FusedFit f = Fit(0.4, 0.3, 0.2, 0.001, 5000);
    f.box = Error{ErrorCode::kInsufficientData, "no top face"};
    EXPECT_EQ(CheckFusedFit(f, refuse)->code, ErrorCode::kInsufficientData);

    // The smallest side judged is the smaller of width and height.
    EXPECT_EQ(CheckFusedFit(Fit(0.4, 0.3, 0.02, 0.001, 5000), refuse)->code,
              ErrorCode::kObjectTooSmall);
    EXPECT_EQ(CheckFusedFit(Fit(0.4, 0.02, 0.2, 0.001, 5000), refuse)->code,
              ErrorCode::kObjectTooSmall);

    f = Fit(0.4, 0.3, 0.2, 0.001, 5000);
    f.consistency.inconsistent_views = {3};
    f.consistency.worst_view = 3;
    f.consistency.worst_inlier_fraction = 0.4;
    auto why = CheckFusedFit(f, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kObjectMoved);
    EXPECT_NE(why->message.find("view 3"), std::string::npos) << why->message;

    EXPECT_EQ(CheckFusedFit(Fit(0.4, 0.3, 0.2, refuse.max_face_sigma_m * 1.2, 5000), refuse)->code,
              ErrorCode::kRegistrationFailed);
}

// Appends the sides and the top of the block [x0, x1] x [y0, y1] x [0, h], every `step`.
void AddBlock(FusedCloud& cloud, double x0, double x1, double y0, double y1, double h,
              double step = 0.005) {
    auto put = [&cloud](double x, double y, double z) {
        cloud.points.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                  static_cast<float>(z));
        cloud.view.push_back(0);
    };
    for (double z = 0.0; z <= h; z += step) {
        for (double x = x0; x <= x1; x += step) {
            put(x, y0, z);
            put(x, y1, z);
        }
        for (double y = y0; y <= y1; y += step) {
            put(x0, y, z);
            put(x1, y, z);
        }
    }
    for (double x = x0; x <= x1; x += step) {
        for (double y = y0; y <= y1; y += step) put(x, y, h);
    }
}

TEST(CheckSingleObject, OneBlockIsOneObject) {
    FusedCloud cloud;
    AddBlock(cloud, -0.15, 0.15, -0.1, 0.1, 0.2);
    EXPECT_FALSE(CheckSingleObject(cloud, cloud.table, RefusalConfig{}).has_value());
}

TEST(CheckSingleObject, TwoSeparateBlocksAreMultipleObjects) {
    // A 0.3 x 0.2 parcel and a 0.15 x 0.1 one, 5 cm apart (5 empty 1 cm cells between them).
    FusedCloud cloud;
    AddBlock(cloud, -0.2, 0.1, -0.1, 0.1, 0.2);
    AddBlock(cloud, 0.15, 0.3, -0.05, 0.05, 0.15);
    auto why = CheckSingleObject(cloud, cloud.table, RefusalConfig{});
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kMultipleObjects);
    EXPECT_NE(why->message.find("2 separate objects"), std::string::npos) << why->message;

    // Blocks that touch (the second against the first's +x face) are one footprint.
    FusedCloud touching;
    AddBlock(touching, -0.2, 0.1, -0.1, 0.1, 0.2);
    AddBlock(touching, 0.1, 0.25, -0.05, 0.05, 0.15);
    EXPECT_FALSE(CheckSingleObject(touching, touching.table, RefusalConfig{}).has_value());
}

TEST(CheckSingleObject, ASpeckBelowTheMinimumShareIsNotAnObject) {
    // The block's footprint covers 31 x 21 = 651 one-centimetre cells; a 2 x 2 cm speck (a
    // scrap, a flying pixel cluster) 4 cm beside it holds 9 cells or fewer, under 5%.
    const RefusalConfig refuse;
    FusedCloud cloud;
    AddBlock(cloud, -0.15, 0.15, -0.1, 0.1, 0.2);
    AddBlock(cloud, 0.19, 0.21, -0.01, 0.01, 0.05);
    EXPECT_FALSE(CheckSingleObject(cloud, cloud.table, refuse).has_value());
    // Points lower than two cells (2 cm) are table, not footprint: a flat scrap is no object
    // however large.
    FusedCloud flat;
    AddBlock(flat, -0.15, 0.15, -0.1, 0.1, 0.2);
    AddBlock(flat, 0.2, 0.35, -0.1, 0.1, 0.015);
    EXPECT_FALSE(CheckSingleObject(flat, flat.table, refuse).has_value());
    // The same speck counts where the share is lowered below it.
    RefusalConfig strict = refuse;
    strict.min_object_share = 0.001;
    auto why = CheckSingleObject(cloud, cloud.table, strict);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kMultipleObjects);
}

TEST(CheckSingleObject, LoneReadingsInTheGapDoNotJoinTwoParcels) {
    // Two parcels 2.5 cm apart, and in the gap a lone reading every other centimetre along it
    // (mixed pixels at the depth step between them), each touching both footprints' cells. The
    // parcels are read every 2.5 mm (16 readings a centimetre of top, as a fused cloud holds).
    FusedCloud cloud;
    AddBlock(cloud, -0.2, -0.0125, -0.1, 0.1, 0.25, 0.0025);
    AddBlock(cloud, 0.0125, 0.15, -0.08, 0.08, 0.12, 0.0025);
    for (double y = -0.075; y <= 0.075; y += 0.02) {
        cloud.points.emplace_back(-0.005f, static_cast<float>(y), 0.1f);
        cloud.points.emplace_back(0.005f, static_cast<float>(y), 0.1f);
        cloud.view.push_back(0);
        cloud.view.push_back(0);
    }
    // The views that look down the gap read the table along it.
    Points table;
    for (double y = -0.1; y <= 0.1; y += 0.0025) {
        for (double x = -0.01; x <= 0.01; x += 0.0025) {
            table.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0f);
        }
    }
    auto why = CheckSingleObject(cloud, table, RefusalConfig{});
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kMultipleObjects);

    // A sparse top is still one surface: a reading a cell, the rim's cells as thin as the
    // footprint's median, none of them dropped.
    FusedCloud sparse;
    for (int i = -15; i < 15; ++i) {
        for (int j = -10; j < 10; ++j) {  // at the cells' centres
            sparse.points.emplace_back(0.01f * (i + 0.5f), 0.01f * (j + 0.5f), 0.2f);
            sparse.view.push_back(0);
        }
    }
    EXPECT_FALSE(CheckSingleObject(sparse, sparse.table, RefusalConfig{}).has_value());
}

EnclosingCuboid Cuboid(double l, double w, double h, bool cuboid) {
    EnclosingCuboid c;
    c.length_m = l;
    c.width_m = w;
    c.height_m = h;
    c.cuboid = cuboid;
    c.fill = cuboid ? 1.0 : 0.785;
    return c;
}

TEST(CheckEnclosingCuboid, ThinCloudEnvelopeErrorAndSmallObject) {
    const RefusalConfig refuse;
    const std::array<double, 3> certain = {0.001, 0.001, 0.001};
    const FusedFit fit = Fit(0.4, 0.3, 0.2, 0.001, 5000);
    EXPECT_FALSE(
        CheckEnclosingCuboid(fit, Cuboid(0.4, 0.3, 0.2, true), certain, refuse).has_value());

    // Too few fused points: NO_OBJECT, whatever the envelope says.
    const FusedFit thin = Fit(0.4, 0.3, 0.2, 0.001, refuse.min_object_points - 1);
    EXPECT_EQ(CheckEnclosingCuboid(thin, Cuboid(0.4, 0.3, 0.2, true), certain, refuse)->code,
              ErrorCode::kNoObject);
    // The envelope's own error.
    const Result<EnclosingCuboid> none = Error{ErrorCode::kInsufficientData, "no cells"};
    EXPECT_EQ(CheckEnclosingCuboid(fit, none, certain, refuse)->code, ErrorCode::kInsufficientData);
    // The smaller of width and height below 3 cm, for cuboids and other shapes alike.
    EXPECT_EQ(CheckEnclosingCuboid(fit, Cuboid(0.4, 0.02, 0.2, true), certain, refuse)->code,
              ErrorCode::kObjectTooSmall);
    EXPECT_EQ(CheckEnclosingCuboid(fit, Cuboid(0.4, 0.3, 0.025, false), certain, refuse)->code,
              ErrorCode::kObjectTooSmall);
    EXPECT_FALSE(
        CheckEnclosingCuboid(fit, Cuboid(0.4, refuse.min_dimension_m, 0.2, true), certain, refuse)
            .has_value());
}

TEST(CheckEnclosingCuboid, UncertainWhenADimensionsBoundExceedsTheLimit) {
    const RefusalConfig refuse;
    const FusedFit fit = Fit(0.4, 0.3, 0.2, 0.001, 5000);
    for (std::size_t i = 0; i < 3; ++i) {
        std::array<double, 3> u = {0.002, 0.002, 0.002};
        u[i] = refuse.max_uncertainty_m;  // at the limit: reported
        EXPECT_FALSE(CheckEnclosingCuboid(fit, Cuboid(0.4, 0.3, 0.2, true), u, refuse).has_value())
            << i;
        u[i] = refuse.max_uncertainty_m * 1.2;
        auto why = CheckEnclosingCuboid(fit, Cuboid(0.4, 0.3, 0.2, true), u, refuse);
        ASSERT_TRUE(why.has_value()) << i;
        EXPECT_EQ(why->code, ErrorCode::kUncertain);
        EXPECT_NE(why->message.find("12.0 mm"), std::string::npos) << why->message;
        // Irregular shapes are judged the same way.
        EXPECT_EQ(CheckEnclosingCuboid(fit, Cuboid(0.4, 0.3, 0.2, false), u, refuse)->code,
                  ErrorCode::kUncertain);
    }
}

TEST(ExplainMultipath, AnUncertainRefusalSaysHowMuchIsATimeOfFlightCamerasMultipath) {
    MeasurementReason uncertain{ErrorCode::kUncertain, "a dimension is uncertain by 12.0 mm"};
    ExplainMultipath(uncertain, 0.0114);
    EXPECT_NE(uncertain.message.find("multipath correction alone is 11.4 mm"), std::string::npos)
        << uncertain.message;
    EXPECT_NE(uncertain.message.find("matte dark table top"), std::string::npos);
    // Nothing to add without multipath, nor to another refusal.
    MeasurementReason plain{ErrorCode::kUncertain, "a dimension is uncertain by 12.0 mm"};
    ExplainMultipath(plain, 0.0);
    EXPECT_EQ(plain.message, "a dimension is uncertain by 12.0 mm");
    MeasurementReason unseen{ErrorCode::kInsufficientData, "a side was never seen"};
    ExplainMultipath(unseen, 0.0114);
    EXPECT_EQ(unseen.message, "a side was never seen");
}

TEST(CheckEnclosingCuboid, ViewConsistencyAndFlatFacesJudgeCuboidsOnly) {
    const RefusalConfig refuse;
    const std::array<double, 3> certain = {0.001, 0.001, 0.001};
    // A view off the box, and faces rougher than the limit: a tube's side is where each view's
    // tangent is, so neither says anything about an irregular object.
    FusedFit off_view = Fit(0.16, 0.16, 0.3, 0.001, 5000);
    off_view.consistency.inconsistent_views = {4};
    off_view.consistency.worst_view = 4;
    off_view.consistency.worst_inlier_fraction = 0.5;
    const FusedFit rough = Fit(0.16, 0.16, 0.3, refuse.max_face_sigma_m * 1.5, 5000);
    EXPECT_FALSE(CheckEnclosingCuboid(off_view, Cuboid(0.16, 0.16, 0.3, false), certain, refuse)
                     .has_value());
    EXPECT_FALSE(
        CheckEnclosingCuboid(rough, Cuboid(0.16, 0.16, 0.3, false), certain, refuse).has_value());
    // The same for a cuboid: OBJECT_MOVED, naming the view, and REGISTRATION_FAILED.
    auto why = CheckEnclosingCuboid(off_view, Cuboid(0.16, 0.16, 0.3, true), certain, refuse);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(why->code, ErrorCode::kObjectMoved);
    EXPECT_NE(why->message.find("view 4"), std::string::npos) << why->message;
    EXPECT_EQ(CheckEnclosingCuboid(rough, Cuboid(0.16, 0.16, 0.3, true), certain, refuse)->code,
              ErrorCode::kRegistrationFailed);
    // Without a box fit there are no faces to judge a cuboid by either.
    FusedFit no_box = off_view;
    no_box.box = Error{ErrorCode::kInsufficientData, "no top face"};
    EXPECT_FALSE(
        CheckEnclosingCuboid(no_box, Cuboid(0.16, 0.16, 0.3, true), certain, refuse).has_value());
}

TEST(RefusalConfig, ValidateNamesTheField) {
    RefusalConfig c;
    EXPECT_TRUE(c.Validate().ok());
    c.max_face_sigma_m = 0.0;
    auto s = c.Validate();
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::kInvalidConfig);
    EXPECT_NE(s.error().message.find("refusal.max_face_sigma_m"), std::string::npos);
}

}  // namespace
}  // namespace boxd
