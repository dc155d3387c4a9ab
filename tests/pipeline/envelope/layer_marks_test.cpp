// The marks of an outer layer's cells on hand-made surfaces: a smooth cap's top above its cell's
// mean by a 24th of the cell means' negative Laplacian, nothing on a flat top, noisy or not, and
// no mark where a neighbour is another surface.
#include "pipeline/envelope/layer_marks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace boxd::envelope {
namespace {

constexpr double kCell = 0.012;

// A 7 x 7 grid of cells over [-3.5, 3.5] cells, read every millimetre on the height s(a, b).
template <typename Height>
CellGrid<LayerCell> Read(Height s) {
    CellGrid<LayerCell> grid(-3.5 * kCell, 3.5 * kCell, -3.5 * kCell, 3.5 * kCell, kCell, kCell);
    for (double a = -3.5 * kCell + 0.0005; a < 3.5 * kCell; a += 0.001) {
        for (double b = -3.5 * kCell + 0.0005; b < 3.5 * kCell; b += 0.001) {
            grid.At(a, b)->Add3(a, b, s(a, b));
        }
    }
    return grid;
}

TEST(MarkCapTops, ACapsTopStandsAboveItsCellsMeanByItsCurvature) {
    // A bag's crown: curvatures of 1 / 0.2 m and 1 / 0.3 m.
    const double kx = 1.0 / 0.2, ky = 1.0 / 0.3;
    auto grid = Read([&](double a, double b) { return 0.3 - (kx * a * a + ky * b * b) / 2.0; });
    MarkCapTops(&grid, 0.0005, EnvelopeConfig{});
    const LayerCell& centre = *grid.CellAt(3, 3);
    EXPECT_NEAR(centre.cap_above_mean_m, (kx + ky) * kCell * kCell / 24.0, 2e-6);
    // Its mean plus the mark is the crown's height.
    EXPECT_NEAR(centre.Mean() + centre.cap_above_mean_m, 0.3, 3e-6);
}

TEST(MarkCapTops, AFlatTopIsNoCap) {
    auto grid = Read([](double, double) { return 0.3; });
    MarkCapTops(&grid, 0.0005, EnvelopeConfig{});
    for (const LayerCell& c : grid.cells) EXPECT_NEAR(c.cap_above_mean_m, 0.0, 1e-9);
}

TEST(MarkCapTops, AFlatTopsNoiseIsNoCap) {
    // A top read with 1.5 mm of noise, a dozen readings a cell: the means scatter by 0.4 mm, and
    // half the cells have a negative Laplacian; the noise is no curvature.
    constexpr double kSigma = 0.0015;
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, kSigma);
    int marked = 0, cells = 0;
    for (int trial = 0; trial < 20; ++trial) {
        CellGrid<LayerCell> grid(-3.5 * kCell, 3.5 * kCell, -3.5 * kCell, 3.5 * kCell, kCell,
                                 kCell);
        for (double a = -3.5 * kCell + 0.001; a < 3.5 * kCell; a += 0.003) {
            for (double b = -3.5 * kCell + 0.001; b < 3.5 * kCell; b += 0.004) {
                grid.At(a, b)->Add3(a, b, 0.3 + noise(rng));
            }
        }
        MarkCapTops(&grid, kSigma, EnvelopeConfig{});
        for (const LayerCell& c : grid.cells) {
            ++cells;
            marked += c.cap_above_mean_m > 0.0;
        }
    }
    // Three standard errors: hardly ever by noise.
    EXPECT_LE(marked, cells / 100);
}

TEST(MarkCapTops, ANeighbourBeyondTheLayerIsAnotherSurface) {
    // The crown, with the cell left of the centre 5 cm lower (an opened panel's tip beside it):
    // more than the layer's depth (5 sigma) away, so the centre is not marked from it.
    const double k = 1.0 / 0.2;
    auto grid = Read([&](double a, double b) {
        const bool left = a >= -1.5 * kCell && a < -0.5 * kCell && std::abs(b) < 0.5 * kCell;
        return 0.3 - k * (a * a + b * b) / 2.0 - (left ? 0.05 : 0.0);
    });
    MarkCapTops(&grid, 0.0005, EnvelopeConfig{});
    EXPECT_EQ(grid.CellAt(3, 3)->cap_above_mean_m, 0.0);
}

}  // namespace
}  // namespace boxd::envelope
