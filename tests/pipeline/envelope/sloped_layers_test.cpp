// Known-answer tests of a sloped surface's outer layer (pipeline/envelope/sloped_layers.h): a
// face sloping across its cells is judged however little noise it carries, front and back, where
// it could pass its row's judged cells, and so is a face turned farther that goes down
// outward; a ridge's two faces, a wall turned sideways and a face with mixed pixels standing off
// it are not; pyramids read with little noise, a low one too, are bounded by their faces
// instead of refused, and a thin fin standing out of a box is still refused as an outline that
// cannot be bounded.
#include "pipeline/envelope/sloped_layers.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "pipeline/envelope/support_envelope.h"

namespace boxd::envelope {
namespace {

constexpr double kSigma = 0.0003;  // a third of a millimetre: the layer is 1.5 mm deep

// The outer layers, front and back, of the 12 mm cells of 0 <= across, up < 0.048 m over
// readings of `along(t, z)` every `spacing` m (noise kSigma), with `extra` readings added: each
// cell's readings within the layer's depth of its outermost (CutLevelLayers, as support_envelope's
// BuildLayers takes them), and then (with `sloped`) the sloped surfaces' layers.
Layers Fill(const std::function<double(double, double)>& along,
            const std::vector<Eigen::Vector3d>& extra = {}, double spacing = 0.001,
            bool sloped = true) {
    const EnvelopeConfig config;
    Layers out{CellGrid<LayerCell>(0.0, 0.048, 0.0, 0.048, 0.012, 0.012),
               CellGrid<LayerCell>(0.0, 0.048, 0.0, 0.048, 0.012, 0.012)};
    std::mt19937 rng(1);
    std::normal_distribution<double> noise(0.0, kSigma);
    std::vector<Eigen::Vector3d> tzs;
    for (double z = spacing / 2; z < 0.048; z += spacing) {
        for (double t = spacing / 2; t < 0.048; t += spacing)
            tzs.emplace_back(t, z, along(t, z) + noise(rng));
    }
    tzs.insert(tzs.end(), extra.begin(), extra.end());
    std::vector<long> cell(tzs.size(), -1);
    for (std::size_t i = 0; i < tzs.size(); ++i) {
        if (const LayerCell* c = out.front.At(tzs[i].x(), tzs[i].y())) {
            cell[i] = static_cast<long>(c - out.front.cells.data());
        }
    }
    const LayerReadings readings = CutLevelLayers(tzs, cell, 1, 0, kSigma, config, out);
    if (sloped) FillSlopedCells(readings, kSigma, config, out);
    return out;
}

int Judged(const CellGrid<LayerCell>& grid) {
    int n = 0;
    for (const LayerCell& c : grid.cells) n += c.n >= EnvelopeConfig{}.min_cell_points ? 1 : 0;
    return n;
}

TEST(SlopedLayers, AFaceSlopingAcrossItsCellsIsJudgedWhereALevelLayerHoldsASliver) {
    // A wedge's face seen along its slope: 1.3 m in per metre up (its normal 52 degrees from
    // the direction), 16 mm over a cell against a 1.5 mm layer, read every 2 mm.
    auto face = [](double, double z) { return 0.1 - 1.3 * z; };
    const Layers level = Fill(face, {}, 0.002, false);
    EXPECT_EQ(Judged(level.front), 0);
    EXPECT_EQ(Judged(level.back), 0);
    const Layers f = Fill(face, {}, 0.002);
    EXPECT_EQ(Judged(f.front), 16);
    EXPECT_EQ(Judged(f.back), 16);  // the same face seen from behind (mirrored)
    for (std::size_t k = 0; k < f.front.cells.size(); ++k) {
        // Each cell holds the outer part of each of its sub-cells' patch of the face, and its
        // mean lies on the face.
        const LayerCell &c = f.front.cells[k], &b = f.back.cells[k];
        EXPECT_NEAR(c.Mean(), face(0.0, c.Centroid().y()), 3.0 * kSigma);
        EXPECT_NEAR(-b.Mean(), face(0.0, b.Centroid().y()), 3.0 * kSigma);
        EXPECT_GT(c.n, level.front.cells[k].n);
    }
}

TEST(SlopedLayers, ACellThatCannotPassItsRowsJudgedCellsIsLeftAsItWas) {
    // The first column of cells is a wall facing the direction 0.2 m out (judged by its level
    // layer); the rest slope as above, 0.1 m out at most: read at their means they cannot pass
    // the wall, and only the wall's cells are judged.
    const Layers f =
        Fill([](double t, double z) { return t < 0.012 ? 0.2 : 0.1 - 1.3 * z; }, {}, 0.002);
    for (int j = 0; j < f.front.nb; ++j) {
        for (int i = 0; i < f.front.na; ++i) {
            EXPECT_EQ(f.front.cells[j * f.front.na + i].n >= 12, i == 0) << i << ", " << j;
        }
    }
}

TEST(SlopedLayers, AFaceGoingDownOutwardTurnedFartherIsJudgedOnTheFace) {
    // Rising half a metre per metre outward (2 m in per metre up): its normal 63 degrees from
    // the direction, a low pyramid's face. Each cell is judged, marked as turned away, its mean
    // on the face. Seen from behind it rises outward: its cells there hold the face's upper
    // end, which bounds nothing, and stay unjudged.
    auto face = [](double, double z) { return 0.1 - 2.0 * z; };
    EXPECT_EQ(Judged(Fill(face, {}, 0.002, false).front), 0);
    const Layers f = Fill(face, {}, 0.002);
    EXPECT_EQ(Judged(f.front), 16);
    EXPECT_EQ(Judged(f.back), 0);
    for (const LayerCell& c : f.front.cells) {
        EXPECT_TRUE(c.turned_away);
        EXPECT_NEAR(c.Mean(), face(0.0, c.Centroid().y()), 3.0 * kSigma);
    }
}

TEST(SlopedLayers, AWallTurnedSidewaysOrTwoSurfacesSharingACellStayUnjudged) {
    // An upright wall turned 63 degrees from the direction (2 m in per metre across): its cells
    // hold its end, which goes down no way outward.
    const Layers wall = Fill([](double t, double) { return 0.1 - 2.0 * t; }, {}, 0.002);
    EXPECT_EQ(Judged(wall.front), 0);
    EXPECT_EQ(Judged(wall.back), 0);
    // A ridge running across the cells 18 mm up, read every 2 mm: its two faces meet in the
    // second row of cells, which keeps its level layer (its crest); the rows clear of it, a
    // face each, are judged.
    auto ridge = [](double, double z) { return 0.1 - 0.8 * std::abs(z - 0.018); };
    const Layers level = Fill(ridge, {}, 0.002, false), f = Fill(ridge, {}, 0.002);
    for (int j = 0; j < f.front.nb; ++j) {
        for (int i = 0; i < f.front.na; ++i) {
            const std::size_t k = static_cast<std::size_t>(j * f.front.na + i);
            if (j == 1) {
                EXPECT_EQ(f.front.cells[k].n, level.front.cells[k].n) << i << ", " << j;
            } else {
                EXPECT_GE(f.front.cells[k].n, 12) << i << ", " << j;
            }
        }
    }
}

TEST(SlopedLayers, MixedPixelsStandingOffTheFaceLeaveItsCellUnjudged) {
    auto face = [](double, double z) { return 0.1 - 1.3 * z; };
    // Three readings a centimetre outside the face in the first cell, as mixed pixels between
    // a foot and the table beyond it read.
    const std::vector<Eigen::Vector3d> strays{{0.003, 0.004, 0.1 - 1.3 * 0.004 + 0.01},
                                              {0.007, 0.005, 0.1 - 1.3 * 0.005 + 0.01},
                                              {0.010, 0.009, 0.1 - 1.3 * 0.009 + 0.01}};
    const Layers f = Fill(face, strays, 0.002);
    EXPECT_LT(f.front.cells[0].n, 12);
    EXPECT_EQ(Judged(f.front), 15);
}

// Twelve cameras round the object, a metre away and 0.7 m up.
void AddCameras(Surface& s) {
    for (int k = 0; k < 12; ++k) {
        const double phi = k * M_PI / 6.0;
        s.cameras.emplace_back(std::cos(phi), std::sin(phi), 0.7);
    }
}

// A pyramid on a 0.3 x `w` m base, `h` tall, read every 1.5 mm over its faces above the
// table's band with 0.3 mm of noise, seen from twelve cameras round it.
Surface Pyramid(double w, double h) {
    Surface s;
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, kSigma);
    const double a = 0.15, b = w / 2.0;
    for (double x = -a; x <= a; x += 0.0015) {
        for (double y = -b; y <= b; y += 0.0015) {
            const double z = h * (1.0 - std::max(std::abs(x) / a, std::abs(y) / b));
            if (z < EnvelopeConfig{}.min_z_m) continue;
            s.points.emplace_back(x, y, z + noise(rng));
        }
    }
    AddCameras(s);
    s.radius = std::hypot(a, b) + 0.01;
    s.top = h + 0.01;
    return s;
}

// The enclosing cuboid of Pyramid(w, h) is measured, 0.3 x w x h within 3 mm.
void ExpectBoundedByItsFaces(double w, double h) {
    const auto cuboid = EnvelopeCuboid(Pyramid(w, h), kSigma, kSigma, EnvelopeConfig{});
    ASSERT_TRUE(cuboid.ok()) << cuboid.error().message;
    EXPECT_NEAR(cuboid->length_m, 0.30, 0.003);
    EXPECT_NEAR(cuboid->width_m, w, 0.003);
    EXPECT_NEAR(cuboid->height_m, h, 0.003);
}

TEST(SlopedLayers, APyramidReadWithLittleNoiseIsBoundedByItsFaces) {
    // Its corner ridges run down to the base's corners, and its faces slope across every cell
    // of the diagonal directions: a layer of 1.5 mm held too few of their readings to judge, and
    // the outline was refused as stopping well short of its readings.
    ExpectBoundedByItsFaces(0.20, 0.15);
}

TEST(SlopedLayers, ALowPyramidIsBoundedByItsFacesGoingDownOutward) {
    // 60 mm tall on a 0.3 x 0.24 m base: its faces rise 0.4 and 0.5 metres per metre, their
    // normals 63 and 68 degrees or more from every level direction. No cell of them faces a
    // direction within 60 degrees, and the outline was refused as stopping well short of its
    // readings; read as facing ones are, they carry the faces down to the table.
    ExpectBoundedByItsFaces(0.24, 0.06);
}

TEST(SlopedLayers, AThinFinStandingOutOfABoxIsStillRefusedAsUnbounded) {
    // A 0.2 m cube's sides and top read every 2 mm, and a fin 1 mm thick standing 40 mm out of
    // one side, read every 3 mm on both its faces: its faces run along the direction it stands
    // out in (no surface faces that way), so its cells hold too few readings to judge, sloped or
    // not, and the outline stops short of its readings there.
    Surface s;
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, kSigma);
    auto add = [&](double x, double y, double z) {
        s.points.emplace_back(x + noise(rng), y + noise(rng), z + noise(rng));
    };
    const double h = 0.1;
    for (double a = -0.1; a <= 0.1; a += 0.002) {
        for (double z = 0.014; z <= h; z += 0.002) {
            for (double side : {-0.1, 0.1}) {
                add(side, a, z);
                add(a, side, z);
            }
        }
        for (double b = -0.1; b <= 0.1; b += 0.002) add(a, b, h);
    }
    for (double x = 0.1; x <= 0.14; x += 0.003) {
        for (double z = 0.02; z <= 0.08; z += 0.003) {
            add(x, -0.0005, z);
            add(x, 0.0005, z);
        }
    }
    AddCameras(s);
    s.radius = 0.16;
    s.top = h + 0.01;
    const auto cuboid = EnvelopeCuboid(s, kSigma, kSigma, EnvelopeConfig{});
    ASSERT_FALSE(cuboid.ok());
    EXPECT_EQ(cuboid.error().code, ErrorCode::kInsufficientData);
    EXPECT_NE(cuboid.error().message.find("cannot be bounded"), std::string::npos)
        << cuboid.error().message;
}

}  // namespace
}  // namespace boxd::envelope
