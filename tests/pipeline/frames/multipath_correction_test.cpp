// A time-of-flight camera's multipath taken out of a view (pipeline/frames/multipath_correction.h):
// the synthetic station renders an exact view with and without its multipath; corrected from its
// own readings, the view's surfaces come back to within a tenth of the error, and a camera
// without multipath is left alone.
#include "pipeline/frames/multipath_correction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "drivers/sim/synthetic_station.h"

namespace boxd {
namespace {

// An exact view (no noise) of a 0.40 x 0.30 x 0.25 box turned 30 degrees, with the time-of-flight
// camera's multipath of reflectance `albedo`, in metres.
DepthMap View(double albedo) {
    SyntheticStationConfig c;
    c.box = {0.40, 0.30, 0.25, 0.0, 0.0, 30.0};
    c.noise = NoiseModel::kNone;
    c.angle_error_deg = 0.0;
    c.camera.depth_unit_m = 0.0001;
    SensorNoiseParams exact = DefaultSensorNoise(NoiseModel::kNone);
    exact.multipath_albedo = albedo;
    c.sensor_noise = exact;
    const DepthImage img = RenderDepthFrame(MakeSyntheticScene(c), 0.0, 1, 0);
    DepthMap d(img.width, img.height);
    for (std::size_t i = 0; i < img.pixels.size(); ++i) {
        d.z_m[i] = static_cast<float>(img.pixels[i] * c.camera.depth_unit_m);
    }
    return d;
}

double Percentile(std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * (v.size() - 1))];
}

TEST(MultipathCorrection, AViewCorrectedFromItsOwnReadingsComesBackToTheTruth) {
    const DepthMap truth = View(0.0), read = View(0.5);
    StationCalibration calibration;
    calibration.multipath_albedo = 0.5;
    const CameraIntrinsics camera;  // the synthetic station's
    const MultipathCorrection corrected = CorrectMultipath(read, camera, calibration);
    std::vector<double> before, after;
    int dropped = 0;
    for (std::size_t i = 0; i < truth.z_m.size(); ++i) {
        if (!(truth.z_m[i] > 0.0f) || !(read.z_m[i] > 0.0f)) continue;
        before.push_back(read.z_m[i] - truth.z_m[i]);
        if (!(corrected.depth.z_m[i] > 0.0f)) {
            ++dropped;
            continue;
        }
        after.push_back(corrected.depth.z_m[i] - truth.z_m[i]);
    }
    ASSERT_GT(before.size(), 100000u);
    std::vector<double> before_abs, after_abs;
    for (double e : before) before_abs.push_back(std::abs(e));
    for (double e : after) after_abs.push_back(std::abs(e));
    // Readings more than a third of whose light came another way (a wall at grazing incidence)
    // are taken out: a few per cent.
    EXPECT_GT(dropped, 0);
    EXPECT_LT(dropped, static_cast<int>(before.size()) / 20);
    EXPECT_GT(Percentile(before_abs, 0.95), 0.005);  // millimetres to take out
    // Nine tenths of the error taken out; the object's typical correction is the walls'.
    EXPECT_LT(Percentile(after_abs, 0.95), 0.1 * Percentile(before_abs, 0.95));
    EXPECT_GT(corrected.largest_m, Percentile(before_abs, 0.95));
    EXPECT_GT(corrected.share.walls_m, 0.005);
    EXPECT_LT(corrected.share.object_m, corrected.largest_m);
    // The box's walls are corrected more than its top, which nothing lights.
    EXPECT_GT(corrected.share.walls_m, corrected.share.object_m);
}

// Samples every 8 pixels of two surfaces 1 m away meeting at column 10: the left one square to
// the camera (its error 0, as a top nothing lights), the right receding 10 mm over the 6 pixels
// to its samples (its error 10 mm, as a lit wall); two rows of samples, three columns.
struct Edge {
    static constexpr int kStride = 8, kColumns = 3, kWidth = 24, kEdge = 10;
    static constexpr double kRecede = (1.0 - 1.0 / 1.01) / 6.0;  // 1/z per pixel
    static double Depth(int u) { return u <= kEdge ? 1.0 : 1.0 / (1.0 - kRecede * (u - kEdge)); }
    std::vector<MultipathSurface> grid;
    std::vector<MultipathLight> errors;
    Edge() {
        for (int row = 0; row < 2; ++row) {
            for (int col = 0; col < kColumns; ++col) {
                const bool wall = col * kStride > kEdge;
                MultipathSurface s;
                s.valid = true;
                s.z_m = Depth(col * kStride);
                s.du_inverse_z = wall ? -kRecede : 0.0;
                grid.push_back(s);
                errors.push_back({wall ? 0.010 : 0.0, 0.0});
            }
        }
    }
    // The error and how far apart the surfaces' errors lie for a reading at column u, row 4.
    std::pair<float, float> At(int u) const {
        std::vector<float> z(static_cast<std::size_t>(kWidth) * 16, 0.0f);
        z[4 * kWidth + u] = static_cast<float>(Depth(u));
        std::vector<float> apart;
        const std::vector<float> e =
            MultipathPixelErrors(grid, errors, kColumns, kStride, z, kWidth,
                                 MultipathSpread::kInsideOrSmallest, 0.004, &apart);
        return {e[4 * kWidth + u], apart[4 * kWidth + u]};
    }
};

TEST(MultipathCorrection, AReadingWhereTwoSurfacesMeetTakesNeithersErrorBetweenThem) {
    const Edge edge;
    // At the edge the reading lies on both planes: the samples round it are all "on its
    // surface", but they are two surfaces. Their bilinear mean (2.5 mm) would move a top's
    // reading by a share of its wall's error; it takes the smaller, and says how far apart they
    // lie.
    const auto [at_edge, apart] = edge.At(Edge::kEdge);
    EXPECT_FLOAT_EQ(at_edge, 0.0f);
    EXPECT_FLOAT_EQ(apart, 0.010f);
    // Off the edge on the wall, only the wall's samples hold it: the wall's error, no doubt.
    const auto [on_wall, wall_apart] = edge.At(14);
    EXPECT_FLOAT_EQ(on_wall, 0.010f);
    EXPECT_FLOAT_EQ(wall_apart, 0.0f);
    // Inside the flat surface, all four samples one surface: their bilinear mean.
    const auto [inside, inside_apart] = edge.At(4);
    EXPECT_FLOAT_EQ(inside, 0.0f);
    EXPECT_FLOAT_EQ(inside_apart, 0.0f);
}

TEST(MultipathCorrection, ALargerImageIsSampledNoMoreDenselyThanAVgaOne) {
    const MultipathSampling vga;
    for (auto [w, h] : {std::pair{640, 480}, std::pair{320, 240}}) {
        const MultipathSampling same = ScaledSampling(vga, w, h);
        EXPECT_EQ(same.stride_px, vga.stride_px);
        EXPECT_EQ(same.source_stride_px, vga.source_stride_px);
    }
    // Four times the pixels: strides twice as wide, the same count of samples and sources.
    const MultipathSampling twice = ScaledSampling(vga, 1280, 960);
    EXPECT_EQ(twice.stride_px, 2 * vga.stride_px);
    EXPECT_EQ(twice.source_stride_px, 2 * vga.source_stride_px);
    // The largest a session may hold (8192 x 8192) stays within a VGA image's count.
    const MultipathSampling largest = ScaledSampling(vga, 8192, 8192);
    const double samples = (8192.0 / largest.stride_px) * (8192.0 / largest.stride_px);
    EXPECT_LE(samples, (640.0 / vga.stride_px) * (480.0 / vga.stride_px));
}

TEST(MultipathCorrection, ACameraWithoutMultipathIsLeftAlone) {
    const DepthMap read = View(0.0);
    const MultipathCorrection same =
        CorrectMultipath(read, CameraIntrinsics{}, StationCalibration{});
    EXPECT_EQ(same.depth.z_m, read.z_m);
    EXPECT_EQ(same.largest_m, 0.0);
}

}  // namespace
}  // namespace boxd
