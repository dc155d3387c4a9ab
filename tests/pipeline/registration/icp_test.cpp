#include "pipeline/registration/icp.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>

#include "pipeline/views/registration_cloud.h"

namespace boxd {
namespace {

// Two visible sides and the top of a box, as one view sees it, with optional noise.
Points BoxView(double sigma, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, sigma);
    Points pts;
    const double l = 0.3, w = 0.2, h = 0.15, step = 0.003;
    for (double z = 0.01; z < h; z += step) {
        for (double v = -w / 2; v <= w / 2; v += step) pts.emplace_back(l / 2 + n(rng), v, z);
        for (double u = -l / 2; u <= l / 2; u += step) pts.emplace_back(u, w / 2 + n(rng), z);
    }
    for (double u = -l / 2; u <= l / 2; u += step) {
        for (double v = -w / 2; v <= w / 2; v += step) pts.emplace_back(u, v, h + n(rng));
    }
    return pts;
}

// BoxView's camera: in front of its +x and +y faces and above.
const Eigen::Vector3f kViewpoint(1.0f, 1.0f, 1.0f);

Points Move(const Points& pts, const Se2& t) {
    Points out;
    for (const auto& p : pts) out.push_back(t.Apply(p));
    return out;
}

TEST(AlignIcp, RecoversKnownPlanarMotionCoarseThenFine) {
    const RegistrationCloudConfig cloud_cfg;
    const Points target_pts = BoxView(0.0005, 1);
    const Se2 truth{0.012, -0.008, 3.0 * M_PI / 180.0};
    // The source is the same scene seen after the inverse motion: truth maps it back.
    const Points source_pts = Move(BoxView(0.0005, 2), truth.Inverse());
    IcpTarget target(BuildRegistrationCloud(target_pts, cloud_cfg, kViewpoint), 0.01);
    const OrientedPoints source =
        BuildRegistrationCloud(source_pts, cloud_cfg, truth.Inverse().Apply(kViewpoint));
    IcpConfig coarse;
    coarse.max_correspondence_m = 0.03;
    const IcpResult c = AlignIcp(source, target, Se2{}, coarse);
    IcpConfig fine;
    fine.max_correspondence_m = 0.006;
    const IcpResult f = AlignIcp(source, target, c.transform, fine);
    EXPECT_TRUE(f.converged);
    EXPECT_NEAR(f.transform.x, truth.x, 0.0005);
    EXPECT_NEAR(f.transform.y, truth.y, 0.0005);
    EXPECT_NEAR(f.transform.yaw, truth.yaw, 0.1 * M_PI / 180.0);
    EXPECT_GT(f.fitness, 0.9);
    EXPECT_LT(f.rmse, 0.002);
    // The information is symmetric positive definite.
    EXPECT_TRUE(f.information.isApprox(f.information.transpose()));
    EXPECT_GT(f.information.determinant(), 0.0);
}

TEST(AlignIcp, WeighsEachPairByTheReadingsOfItsSamples) {
    // The same view as source and target, and beside each source sample of the +x face another
    // 2 mm outside it that stands for a hundredth of the readings: the centroid of the few
    // readings the noise carried into the next voxel. Counted once each, those samples would
    // pull the face half-way out (a millimetre); counted by their readings, by about 0.04 mm.
    const RegistrationCloudConfig cloud_cfg;
    const OrientedPoints view = BuildRegistrationCloud(BoxView(0.0, 5), cloud_cfg, kViewpoint);
    IcpTarget target(view, 0.01);
    OrientedPoints source = view;
    for (std::size_t i = 0; i < view.points.size(); ++i) {
        if (view.normals[i].x() < 0.9f) continue;
        source.points.push_back(view.points[i] + Eigen::Vector3f(0.002f, 0.0f, 0.0f));
        source.normals.push_back(view.normals[i]);
        source.weights.push_back(0.01f);
    }
    ASSERT_GT(source.points.size(), view.points.size() + 100);
    IcpConfig fine;
    fine.max_correspondence_m = 0.008;
    fine.point_to_point_weight = 0.0;
    const IcpResult weighed = AlignIcp(source, target, Se2{}, fine);
    EXPECT_NEAR(weighed.transform.x, 0.0, 0.00006);
    // The same samples counted once each.
    OrientedPoints counted_once = source;
    counted_once.weights.clear();
    const IcpResult once = AlignIcp(counted_once, target, Se2{}, fine);
    EXPECT_LT(once.transform.x, -0.0005);
}

TEST(AlignIcp, ReportsNoOverlap) {
    const RegistrationCloudConfig cloud_cfg;
    const Points pts = BoxView(0.0, 3);
    IcpTarget target(BuildRegistrationCloud(pts, cloud_cfg, kViewpoint), 0.01);
    const OrientedPoints far = BuildRegistrationCloud(Move(pts, Se2{1.0, 0.0, 0.0}), cloud_cfg,
                                                      Se2{1.0, 0.0, 0.0}.Apply(kViewpoint));
    const IcpResult r = AlignIcp(far, target, Se2{}, IcpConfig{});
    EXPECT_FALSE(r.converged);
    EXPECT_EQ(r.fitness, 0.0);
}

// One face (x = 0.15, facing +x, 0.2 m wide) and the top above it: all that two views share
// when each sees the face at its own incidence (four poses a quarter turn apart).
Points SharedFace() {
    Points pts;
    const double step = 0.003;
    for (double z = 0.01; z < 0.15; z += step) {
        for (double y = -0.1; y <= 0.1; y += step) pts.emplace_back(0.15, y, z);
    }
    for (double x = 0.0; x <= 0.15; x += step) {
        for (double y = -0.1; y <= 0.1; y += step) pts.emplace_back(x, y, 0.15);
    }
    return pts;
}

TEST(AlignIcp, KeepsItsStartAlongTheOneFaceTwoViewsShare) {
    // The views differ by 2 mm along the face's normal; the alignment starts 5 mm off along the
    // face. The face fixes the normal; along it only the outlines pull (the point-to-point
    // term), and outlines seen at different incidences end at different places, so the
    // alignment keeps its start there (the turntable model's place) and finds the 2 mm across.
    const RegistrationCloudConfig cloud_cfg;
    const Eigen::Vector3f camera(1.0f, 0.0f, 0.6f);
    IcpTarget target(BuildRegistrationCloud(SharedFace(), cloud_cfg, camera), 0.01);
    const Se2 truth{0.002, 0.0, 0.0};
    const OrientedPoints source = BuildRegistrationCloud(Move(SharedFace(), truth.Inverse()),
                                                         cloud_cfg, truth.Inverse().Apply(camera));
    const Se2 start{0.0, 0.005, 0.0};
    IcpConfig fine;
    fine.max_correspondence_m = 0.01;
    const IcpResult r = AlignIcp(source, target, start, fine);
    EXPECT_NEAR(r.transform.x, truth.x, 0.0005);
    EXPECT_NEAR(r.transform.y, start.y, 0.0002);
    // The slide is free: the face's normals fix it with a few thousandths of the information they
    // give across it.
    const Eigen::Matrix2d planes = r.point_scatter.topLeftCorner<2, 2>();
    EXPECT_LT(planes(1, 1), fine.degenerate_share * planes(0, 0));
    // Left to the outlines (nearest samples of two grids), the alignment moves along the face.
    IcpConfig sliding = fine;
    sliding.degenerate_share = 0.0;
    EXPECT_GT(std::abs(AlignIcp(source, target, start, sliding).transform.y - start.y), 0.0005);
}

TEST(IcpConfig, ValidateNamesField) {
    IcpConfig c;
    c.max_correspondence_m = -1.0;
    const Status s = c.Validate("registration.fine");
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.error().message.find("registration.fine.max_correspondence_m"), std::string::npos);
}

TEST(AlignIcp, TheTwoSidesOfAThinPanelAreNotTheSameSurface) {
    // A 3 mm panel standing in the plane x = 0: one view sees its front (x = 0, from +x), the
    // other its back (x = -0.003, from -x). Within the correspondence gate and parallel, the two
    // sides would pass for one surface and pull the views 3 mm together; their normals face
    // their own cameras, opposite ways, so no pair forms.
    auto side = [](float x) {
        Points pts;
        for (float y = -0.15f; y <= 0.15f; y += 0.003f) {
            for (float z = 0.0f; z <= 0.2f; z += 0.003f) pts.emplace_back(x, y, z);
        }
        return pts;
    };
    const RegistrationCloudConfig cloud_cfg;
    IcpTarget front(BuildRegistrationCloud(side(0.0f), cloud_cfg, Eigen::Vector3f(1, 0, 0.5)),
                    0.01);
    const OrientedPoints back =
        BuildRegistrationCloud(side(-0.003f), cloud_cfg, Eigen::Vector3f(-1, 0, 0.5));
    ASSERT_GT(back.points.size(), 100u);
    const IcpResult r = AlignIcp(back, front, Se2{}, IcpConfig{});
    EXPECT_EQ(r.correspondences, 0);
    EXPECT_FALSE(r.converged);
}

}  // namespace
}  // namespace boxd
