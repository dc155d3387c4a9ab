// The station calibration on synthetic sessions with injected errors: the recorded calibration's
// centre and axis are off and the sensor reads short by a depth offset the recorded calibration
// does not know (it records 0); the calibration must
// recover the true values (SyntheticScene::true_calibration) to 1 mm, 0.1 deg and 2 mm.
#include "calibration/station_calibrator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ostream>

#include "drivers/sim/synthetic_station.h"

namespace boxd {
namespace {

struct Injected {
    std::uint64_t seed;
    double center_error_m;
    double axis_error_deg;
    double depth_offset_m;
};

// How ctest lists a case (instead of its bytes).
void PrintTo(const Injected& inj, std::ostream* os) {
    *os << "seed " << inj.seed << ", centre off " << inj.center_error_m * 1000.0 << " mm, axis off "
        << inj.axis_error_deg << " deg, depth offset " << inj.depth_offset_m * 1000.0 << " mm";
}

SyntheticStationConfig ReferenceStation(const Injected& inj) {
    SyntheticStationConfig c;
    c.box.length_m = 0.32;
    c.box.width_m = 0.26;
    c.box.height_m = 0.30;
    c.box.offset_x_m = 0.04;  // the reference stands anywhere on the table
    c.box.offset_y_m = -0.03;
    c.box.yaw_deg = 25.0;
    c.noise = NoiseModel::kKinect;
    c.seed = inj.seed;
    c.calib_center_error_m = inj.center_error_m;
    c.calib_axis_error_deg = inj.axis_error_deg;
    c.true_depth_offset_m = inj.depth_offset_m;
    // The station never learnt of its sensor's bias: the recorded calibration says 0, so the
    // offset has to be found, not carried over from the session.
    c.calib_depth_offset_error_m = -inj.depth_offset_m;
    return c;
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

CalibrationConfig HeldLens() {
    CalibrationConfig c;
    c.estimate_focal_scale = false;
    return c;
}

class RecoversInjectedErrors : public ::testing::TestWithParam<Injected> {};

TEST_P(RecoversInjectedErrors, CentreAxisAndDepthOffset) {
    const SyntheticStationConfig station = ReferenceStation(GetParam());
    const SyntheticScene scene = MakeSyntheticScene(station);
    auto session = RenderSyntheticSession(station, 12, 2);
    ASSERT_TRUE(session.ok()) << session.error().message;
    auto report =
        CalibrateStation(*session, SyntheticGroundTruth(station.box), HeldLens());
    ASSERT_TRUE(report.ok()) << report.error().code << ": " << report.error().message;

    const StationCalibration& truth = scene.true_calibration;
    const StationCalibration& got = report->calibration;
    const double centre_err = (got.table_center_m - truth.table_center_m).norm();
    const double axis_err = AngleDeg(got.table_axis, truth.table_axis);
    const double offset_err = got.depth_offset_m - truth.depth_offset_m;
    std::printf(
        "seed %llu: centre error %.3f mm (recorded %.1f mm), axis error %.4f deg (recorded %.2f), "
        "depth offset %.2f mm (true %.1f mm, error %.3f mm); sigmas %.4f mm, %.5f deg, %.4f mm; "
        "face rms %.2f mm\n",
        static_cast<unsigned long long>(GetParam().seed), centre_err * 1e3,
        (session->calibration.table_center_m - truth.table_center_m).norm() * 1e3, axis_err,
        AngleDeg(session->calibration.table_axis, truth.table_axis), got.depth_offset_m * 1e3,
        truth.depth_offset_m * 1e3, offset_err * 1e3, report->uncertainty.table_center_m * 1e3,
        report->uncertainty.table_axis_deg, report->uncertainty.depth_offset_m * 1e3,
        report->face_rms_m * 1e3);
    EXPECT_LT(centre_err, 0.001);
    EXPECT_LT(axis_err, 0.1);
    EXPECT_LT(std::abs(offset_err), 0.002);
    EXPECT_EQ(session->calibration.depth_offset_m, 0.0);
    EXPECT_EQ(report->poses_used, 12);
    EXPECT_DOUBLE_EQ(got.depth_scale, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RecoversInjectedErrors,
                         ::testing::Values(Injected{11, 0.01, 1.0, 0.010},
                                           Injected{12, 0.02, 2.0, -0.010},
                                           Injected{13, 0.03, 3.0, 0.006}),
                         [](const ::testing::TestParamInfo<Injected>& info) {
                             return "seed" + std::to_string(info.param.seed);
                         });

}  // namespace
}  // namespace boxd
