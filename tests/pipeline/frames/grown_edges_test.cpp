// Edge growth taken away (pipeline/frames/grown_edges.h): a row whose nearer surface spread its
// depth 3 pixels onto the farther one behind loses those 3 pixels and nothing else, also where
// the step's mixed pixel was refused; a surface without steps, and a growth of 0, lose nothing;
// whether a reading goes does not hang on its own noise.
#include "pipeline/frames/grown_edges.h"

#include <gtest/gtest.h>

namespace boxd {
namespace {

constexpr int kW = 30, kH = 4;

// Rows of a box at 1.0 m on columns [10, 20) before a table at 1.4 m, its depth spread `grown`
// pixels either way (the box's own depth on the table's first pixels); column 0 reads nothing.
DepthMap BoxBeforeTable(int grown) {
    DepthMap d(kW, kH);
    for (int y = 0; y < kH; ++y) {
        for (int x = 1; x < kW; ++x) {
            d.at(x, y) = x >= 10 - grown && x < 20 + grown ? 1.0f + 0.001f * (x - 10) : 1.4f;
        }
    }
    return d;
}

TEST(GrownEdges, TheGrownPixelsGoAndTheSurfaceStays) {
    const DepthMap out = RemoveGrownEdges(BoxBeforeTable(3), 3, FlyingPixelConfig{});
    for (int y = 0; y < kH; ++y) {
        for (int x = 1; x < kW; ++x) {
            const bool grown = (x >= 7 && x < 10) || (x >= 20 && x < 23);
            EXPECT_EQ(out.at(x, y) == 0.0f, grown) << x << "," << y;
        }
        EXPECT_EQ(out.at(0, y), 0.0f);
    }
}

TEST(GrownEdges, AMissingReadingBeforeTheFartherSurfaceIsTheStep) {
    DepthMap grown = BoxBeforeTable(3);
    for (int y = 0; y < kH; ++y) grown.at(23, y) = 0.0f;  // the first of the table's, refused
    const DepthMap out = RemoveGrownEdges(grown, 3, FlyingPixelConfig{});
    for (int y = 0; y < kH; ++y) {
        for (int x = 17; x < kW; ++x) {
            EXPECT_EQ(out.at(x, y) == 0.0f, x >= 20 && x <= 23) << x << "," << y;
        }
    }
}

TEST(GrownEdges, AReadingsOwnNoiseDoesNotDecideWhetherItGoes) {
    // A steep face, 3.5 mm farther a pixel, then the table; 2 pixels are taken off. Column 10
    // has the face's column 12 two pixels away, 7 mm farther: judged from its neighbour, which
    // stands 3.5 mm nearer, no step of 12 mm. Read 6 mm nearer or farther by its noise, it
    // stays either way (judged from its own depth, it would go when read nearer).
    DepthMap face(kW, 1);
    for (int x = 0; x < kW; ++x) face.at(x, 0) = x < 20 ? 1.0f + 0.0035f * x : 1.4f;
    for (const float noise : {-0.006f, 0.006f}) {
        DepthMap noisy = face;
        noisy.at(10, 0) += noise;
        EXPECT_GT(RemoveGrownEdges(noisy, 2, FlyingPixelConfig{}).at(10, 0), 0.0f) << noise;
    }
}

TEST(GrownEdges, WithoutGrowthOrStepsNothingGoes) {
    const DepthMap grown = BoxBeforeTable(3);
    EXPECT_EQ(RemoveGrownEdges(grown, 0, FlyingPixelConfig{}).z_m, grown.z_m);
    // A slope of a millimetre a pixel (a face at 30 degrees) has no step.
    DepthMap ramp(kW, kH);
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) ramp.at(x, y) = 1.0f + 0.001f * x;
    }
    EXPECT_EQ(RemoveGrownEdges(ramp, 4, FlyingPixelConfig{}).z_m, ramp.z_m);
}

}  // namespace
}  // namespace boxd
