// The refusal rules on hand-made stage outputs: each rule fires on its own condition with its
// code, and stays silent just inside its limit.
#include "pipeline/refusal.h"

#include <gtest/gtest.h>

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

    // 20% of 40 alignments rejected is the limit; 9 of 40 is past it.
    EXPECT_FALSE(CheckRegisteredViews(Registered(32, 8, 0.001), 18, refuse).has_value());
    EXPECT_EQ(CheckRegisteredViews(Registered(31, 9, 0.001), 18, refuse)->code,
              ErrorCode::kObjectMoved);

    r = Registered(30, 0, 0.001);
    r.graph.unconstrained_nodes = 5;  // > 25% of 18
    EXPECT_EQ(CheckRegisteredViews(r, 18, refuse)->code, ErrorCode::kRegistrationFailed);
    RegisteredViews none_aligned = Registered(0, 0, 0.0);
    none_aligned.edges.attempted = 30;  // tried, none held
    EXPECT_EQ(CheckRegisteredViews(none_aligned, 18, refuse)->code, ErrorCode::kRegistrationFailed);
    // Views too far apart to share a surface (two or three poses) are not aligned at all: they
    // rest on the turntable model and are not refused for it.
    EXPECT_FALSE(CheckRegisteredViews(Registered(0, 0, 0.0), 3, refuse).has_value());

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
