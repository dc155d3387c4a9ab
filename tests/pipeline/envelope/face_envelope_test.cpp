// Known-answer tests of a face's cells (pipeline/envelope/face_envelope.h) on a hand-made top:
// every view reads the face with its own shift and the sensor's noise, most cells with a dozen
// readings a view and a quarter of it with one or two (a corner some views see obliquely, a stretch
// where the fused cloud keeps few pixels).
#include "pipeline/envelope/face_envelope.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

namespace boxd::envelope {
namespace {

constexpr int kViews = 12;
constexpr double kSigma = 0.0015;      // the sensor's noise per reading
constexpr double kViewShift = 0.0001;  // each view's own error of the face's plane
constexpr int kPatchViews = 4;         // the views that read the sparse patch
constexpr double kL = 0.40, kW = 0.30, kH = 0.20;

// The box the cells are read against: its top at kH, its footprint centred on the origin.
BoxFit Box() {
    BoxFit box;
    box.length_m = kL;
    box.width_m = kW;
    box.height_m = kH;
    box.face_sigma_m = kSigma;
    return box;
}

// A flat top read by every view, a reading every `step` metres, each view on its own jittered
// grid; the quarter x > 0, y > 0 only by kPatchViews of them, every `sparse_step` metres,
// `bump` metres above the top.
FusedCloud Top(unsigned seed, double step, double sparse_step, double bump = 0.0) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, kSigma), shift(0.0, kViewShift);
    std::uniform_real_distribution<double> jitter(0.0, 1.0);
    FusedCloud cloud;
    for (int v = 0; v < kViews; ++v) {
        const double dz = shift(rng);
        for (double x = -kL / 2 + step * jitter(rng); x < kL / 2; x += step) {
            for (double y = -kW / 2 + step * jitter(rng); y < kW / 2; y += step) {
                const bool patch = x > 0.0 && y > 0.0;
                if (patch) continue;
                cloud.points.emplace_back(x, y, kH + dz + noise(rng));
                cloud.view.push_back(static_cast<std::uint16_t>(v));
            }
        }
        if (v >= kPatchViews) continue;
        const double j = sparse_step * jitter(rng);
        for (double x = j; x < kL / 2; x += sparse_step) {
            for (double y = j; y < kW / 2; y += sparse_step) {
                cloud.points.emplace_back(x, y, kH + bump + dz + noise(rng));
                cloud.view.push_back(static_cast<std::uint16_t>(v));
            }
        }
    }
    // The face envelopes read every reading, before the fusion's support test.
    cloud.unfiltered = cloud.points;
    cloud.unfiltered_view = cloud.view;
    return cloud;
}

TEST(FaceEnvelopes, CellsReadWithFewReadingsAViewDoNotStandOutOfAFlatFace) {
    // The quarter's cells get a reading or two from each of four views against the rest's
    // sixteen from twelve: their means of the views' means scatter with the noise of one
    // reading over four views, about four times what the face's pooled spread of the views'
    // means says, and four views' own scatter is a poor guess of it. Known as well as their
    // readings say, they stand out of a flat face on one capture in twenty at most (the
    // false-alarm rate over the face).
    const EnvelopeConfig config;
    int alarms = 0;
    for (unsigned seed = 1; seed <= 40; ++seed) {
        const auto faces = FaceEnvelopes(Top(seed, 0.003, 0.009), Box(), kViews, config);
        alarms += faces[4].excess_m > 0.0 ? 1 : 0;
    }
    std::printf("a flat top's sparse patch stood out on %d of 40 captures\n", alarms);
    EXPECT_LE(alarms, 4);
}

TEST(FaceEnvelopes, ALabelReadWithFewReadingsAViewStillStandsOut) {
    // The same quarter 4 mm proud of the top (a lid): it stands out every time, by about that.
    const EnvelopeConfig config;
    for (unsigned seed = 1; seed <= 10; ++seed) {
        const auto faces = FaceEnvelopes(Top(seed, 0.003, 0.009, 0.004), Box(), kViews, config);
        EXPECT_GT(faces[4].excess_m, 0.002) << "seed " << seed;
        EXPECT_LT(faces[4].excess_m, 0.006) << "seed " << seed;
    }
}

}  // namespace
}  // namespace boxd::envelope
