#include "pipeline/envelope/single_view_cuboid.h"

#include <spdlog/fmt/fmt.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "pipeline/core/median.h"
#include "pipeline/core/student_t.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd::envelope {

namespace {

// The share of a view's readings that may stand outside its top's outline as mixed readings
// and stray noise (boxes: a tenth of one per cent).
constexpr double kStrayShare = 0.01;
// A side the view shows holds at least this many wall readings (four square centimetres at a
// reading every 2 mm); a hidden side holds the few the noise carries round its corners.
constexpr std::size_t kSeenWallReadings = 100;
// A flat wall's readings spread across the line of sight by its noise: their 10-90% range is
// 2.56 noise sigmas. One that spreads beyond two and a half times that is curved (a tube's
// side: 3.3-8 times on one Kinect view from 1 m, the narrowest tube the least; boxes and
// labelled, rounded and bulging cartons: 0.7-1.6 times).
constexpr double kWallRange = 2.563;
constexpr double kCurvedWall = 2.5;
// The top's cells, for the levels it stands at (a strap is wider than a centimetre), and the
// walls' slices, for how far out they stand.
constexpr double kTopCellM = 0.01;
constexpr int kTopCellReadings = 10;

// The sides of the assumed footprint `c` as the view shows them.
struct SeenSides {
    // How far the object reaches beyond its flat top's edge on the sides seen, at most: the
    // outermost 1 cm slice of a wall (its readings' median) against the flat top's outer
    // readings (98%).
    double reach_m = 0.0;
    std::array<int, 2> hidden{};   // per axis (length, width): its sides no wall stands under
    double widest_spread_m = 0.0;  // the widest 10-90% range of a seen wall's readings
};

// How far the top's upper level stands above its median: the 98th percentile of its 1 cm cells'
// median heights over their median. A strap over the top is such a level, a few per cent of the
// cells 1-3 mm up; a flat top's cells scatter by their readings' noise over their count.
double UpperLevel(const std::vector<cv::Point2f>& xy, const std::vector<double>& z) {
    std::map<std::pair<int, int>, std::vector<double>> cells;
    for (std::size_t i = 0; i < xy.size(); ++i) {
        cells[{static_cast<int>(std::floor(xy[i].x / kTopCellM)),
               static_cast<int>(std::floor(xy[i].y / kTopCellM))}]
            .push_back(z[i]);
    }
    std::vector<double> medians;
    for (auto& [key, heights] : cells) {
        if (static_cast<int>(heights.size()) >= kTopCellReadings) {
            medians.push_back(Quantile(heights, 0.5));
        }
    }
    if (medians.size() < 2) return 0.0;
    const double upper = Quantile(medians, 0.98);
    return upper - Quantile(medians, 0.5);
}

SeenSides ReadSeenSides(const FusedCloud& cloud, const EnclosingCuboid& c, double wall_below_m,
                        double flat_band_m, double min_z_m) {
    const Eigen::Vector2d along = c.length_axis, across(-along.y(), along.x());
    std::array<std::vector<double>, 4> wall, flat;  // per side: +length, -length, +width, -width
    std::array<std::map<int, std::vector<double>>, 4> slices;  // per side: the wall by height
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() < min_z_m) continue;
        const Eigen::Vector2d d = Eigen::Vector2d(p.x(), p.y()) - c.center_m;
        const double u = d.dot(along), v = d.dot(across);
        const double eu = std::abs(u) - c.length_m / 2.0, ev = std::abs(v) - c.width_m / 2.0;
        const std::size_t side = eu > ev ? (u > 0.0 ? 0 : 1) : (v > 0.0 ? 2 : 3);
        if (p.z() < wall_below_m) {
            wall[side].push_back(std::max(eu, ev));
            slices[side][static_cast<int>(std::floor(p.z() / kTopCellM))].push_back(
                std::max(eu, ev));
        } else if (std::abs(p.z() - c.height_m) < flat_band_m) {
            flat[side].push_back(std::max(eu, ev));
        }
    }
    SeenSides out;
    for (std::size_t side = 0; side < 4; ++side) {
        if (wall[side].size() < kSeenWallReadings) {
            ++out.hidden[side / 2];
            continue;
        }
        out.widest_spread_m =
            std::max(out.widest_spread_m, Quantile(wall[side], 0.9) - Quantile(wall[side], 0.1));
        double outer = -INFINITY;
        for (auto& [slice, excess] : slices[side]) {
            if (static_cast<int>(excess.size()) >= kTopCellReadings) {
                outer = std::max(outer, Quantile(excess, 0.5));
            }
        }
        const double flat_edge = Quantile(flat[side], 0.98);
        if (std::isfinite(flat_edge) && std::isfinite(outer)) {
            out.reach_m = std::max(out.reach_m, outer - flat_edge);
        }
    }
    return out;
}

// The top as the one view reads it: its readings within `band` of the 99.5% height.
struct TopBand {
    double top = 0.0, band = 0.0;
    std::vector<cv::Point2f> footprint;
    std::vector<double> heights;
    double upper_level = 0.0;  // how far part of the top stands above its median (UpperLevel)
};

// Returns the top band, or INSUFFICIENT_DATA when the highest readings are no top: too few, or
// not horizontal (the upper strip of a wall).
Result<TopBand> ReadTopBand(const FusedCloud& cloud, double noise_sigma,
                            const EnvelopeConfig& config) {
    std::vector<float> z;
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() >= config.min_z_m) z.push_back(p.z());
    }
    if (z.empty()) return Error{ErrorCode::kInsufficientData, "no surface above the table"};
    const auto q = static_cast<long>(0.995 * static_cast<double>(z.size() - 1));
    std::nth_element(z.begin(), z.begin() + q, z.end());
    TopBand t;
    t.top = z[static_cast<std::size_t>(q)];
    t.band = std::max(4.0 * noise_sigma, 0.01);
    for (const Eigen::Vector3f& p : cloud.points) {
        if (std::abs(p.z() - t.top) > t.band) continue;
        t.footprint.emplace_back(p.x(), p.y());
        t.heights.push_back(p.z());
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < t.footprint.size(); ++i) {
        const Eigen::Vector3d p(t.footprint[i].x, t.footprint[i].y, t.heights[i]);
        mean += p;
        outer += p * p.transpose();
    }
    bool horizontal = false;
    if (!t.footprint.empty()) {
        mean /= static_cast<double>(t.footprint.size());
        const Eigen::Matrix3d cov =
            outer / static_cast<double>(t.footprint.size()) - mean * mean.transpose();
        horizontal =
            std::abs(
                Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0).z()) >
            std::cos(M_PI / 6.0);
    }
    if (static_cast<int>(t.footprint.size()) < 10 * config.min_cell_points || !horizontal) {
        return Error{ErrorCode::kInsufficientData,
                     "a single view that shows no top face cannot bound the object"};
    }
    t.upper_level = UpperLevel(t.footprint, t.heights);
    return t;
}

// Returns the cuboid of the top's densely read cells, its height the top's median, with the
// bounds of its edges and height (`top.heights` is reordered). Mixed readings at the top's far
// edge (between the top and the table behind it) lie beyond the edge, sparsely: the top's
// footprint is its densely read cells (a cell twice the readings' spacing holds about four; one
// holding less than half the typical count is edge or stray), whose centres span the top to
// within half a cell at each edge.
Result<EnclosingCuboid> DenseTopCuboid(TopBand& top, double noise_sigma) {
    std::vector<cv::Point2f> raw_hull;
    cv::convexHull(top.footprint, raw_hull);
    const double spacing = std::sqrt(cv::contourArea(raw_hull) / top.footprint.size());
    const double cell = std::max(2.0 * spacing, 0.002);
    std::vector<Eigen::Vector2d> top_xy;
    for (const cv::Point2f& p : top.footprint) top_xy.emplace_back(p.x, p.y);
    const auto counts = CountFootprintCells(top_xy, cell);
    std::vector<int> all_counts;
    for (const auto& [key, n] : counts) all_counts.push_back(n);
    std::nth_element(all_counts.begin(),
                     all_counts.begin() + static_cast<long>(all_counts.size() / 2),
                     all_counts.end());
    const int typical = all_counts[all_counts.size() / 2];
    std::vector<cv::Point2f> dense;
    for (const auto& [key, n] : counts) {
        if (2 * n < typical) continue;
        dense.emplace_back(static_cast<float>((key.first + 0.5) * cell),
                           static_cast<float>((key.second + 0.5) * cell));
    }
    if (dense.size() < 3) {
        return Error{ErrorCode::kInsufficientData, "the top face is too small to bound the object"};
    }
    std::vector<cv::Point2f> hull;
    cv::convexHull(dense, hull);
    // The outermost dense cells straddle the edge: their centres stand within half a cell of it,
    // inside where the cell is mostly top, outside where the edge's mixed readings fill it.
    const cv::RotatedRect rect = cv::minAreaRect(hull);
    const double a = rect.size.width, b = rect.size.height;
    const double angle = rect.angle * M_PI / 180.0;
    EnclosingCuboid c;
    c.center_m = Eigen::Vector2d(rect.center.x, rect.center.y);
    const Eigen::Vector2d axis_a(std::cos(angle), std::sin(angle));
    c.length_axis = a >= b ? axis_a : Eigen::Vector2d(-axis_a.y(), axis_a.x());
    c.length_m = std::max(a, b);
    c.width_m = std::min(a, b);
    std::vector<double>& heights = top.heights;
    std::nth_element(heights.begin(), heights.begin() + static_cast<long>(heights.size() / 2),
                     heights.end());
    c.height_m = heights[heights.size() / 2];
    // An edge is known to within its cell (uniform over it: sigma cell / √12) and the readings'
    // spacing (how far the last reading may stand from the true edge).
    const double edge = std::hypot(cell / std::sqrt(12.0), spacing);
    c.sigma_m = {std::sqrt(2.0) * edge, std::sqrt(2.0) * edge,
                 noise_sigma / std::sqrt(static_cast<double>(heights.size())) + 0.5 * spacing};
    c.fill = std::min(1.0, cv::contourArea(hull) / std::max(a * b, 1e-12));
    return c;
}

// The assumption must hold where the view can test it: a box's sides stand under its top's
// edges, so the view's readings lie within the rectangle, but for the mixed readings at its
// edges and the noise, within the edges' 95% bounds. An object wider below its top (a bag, a
// tube lying, a lower step) shows its sides outside: on one Kinect view from 1 m, a bag's top
// patch read 126 mm short, its sides standing 3-6 cm out of it over two thirds of its readings;
// boxes, L-shapes, standing tubes and bulging cartons kept 99.9% of their readings within 2.5 mm,
// none beyond 7.2 mm, against bounds of 7.6-8 mm. Nor may anything stand above the top: the
// top's own readings reach a band (four noise sigmas, a centimetre at least) above its 99.5%
// height with a Gaussian's tail, about `expected` of them; a few more are a part standing higher
// (a flap opened towards the camera, seen edge-on: 6 to 111 readings of 47,000 on one Kinect
// view from 1 m; boxes and tubes: none).
Status CheckOutline(const FusedCloud& cloud, const EnclosingCuboid& c, const TopBand& top,
                    double noise_sigma, const EnvelopeConfig& config) {
    const Eigen::Vector2d along = c.length_axis, across(-along.y(), along.x());
    const double reach_l = c.length_m / 2.0 + kNormal95 * c.sigma_m[0];
    const double reach_w = c.width_m / 2.0 + kNormal95 * c.sigma_m[1];
    std::size_t readings = 0, outside = 0, above = 0;
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() < config.min_z_m) continue;
        const Eigen::Vector2d d = Eigen::Vector2d(p.x(), p.y()) - c.center_m;
        ++readings;
        outside += std::abs(d.dot(along)) > reach_l || std::abs(d.dot(across)) > reach_w;
        above += p.z() > top.top + top.band;
    }
    if (static_cast<double>(outside) > kStrayShare * static_cast<double>(readings)) {
        return Error{
            ErrorCode::kInsufficientData,
            fmt::format("one view cannot bound the object: {:.0f}% of its readings stand "
                        "outside its top's outline, so it is no box (more poses needed)",
                        100.0 * static_cast<double>(outside) / static_cast<double>(readings))};
    }
    const double expected =
        0.5 * std::erfc(top.band / (noise_sigma * std::sqrt(2.0))) * static_cast<double>(readings);
    if (static_cast<double>(above) > 3.0 + expected + 3.0 * std::sqrt(expected)) {
        return Error{ErrorCode::kInsufficientData,
                     fmt::format("one view cannot bound the object: {} of its readings stand "
                                 "above its top, a part the view hardly sees (more poses needed)",
                                 above)};
    }
    return OkStatus();
}

}  // namespace

Result<EnclosingCuboid> SingleViewCuboid(const FusedCloud& cloud, double noise_sigma,
                                         const EnvelopeConfig& config) {
    auto top = ReadTopBand(cloud, noise_sigma, config);
    if (!top) return top.error();
    auto c = DenseTopCuboid(*top, noise_sigma);
    if (!c) return c.error();
    if (Status fits = CheckOutline(cloud, *c, *top, noise_sigma, config); !fits) {
        return fits.error();
    }
    // The sides it shows tell of the sides it hides. A curved one (a tube's) says nothing of
    // where the far side ends. A side that reaches beyond the flat top's edge (rounded edges, a
    // bulge) says the hidden sides may too, by more than the view sees of them: their far
    // rounding turns away from the camera. Rounded cartons read 5-17 mm short from one view with
    // bounds of 7-8 mm, their seen sides reaching 3-8 mm beyond the flat top. A hidden side's 95%
    // range is taken as twice the reach, from the top's edge outwards.
    const SeenSides seen =
        ReadSeenSides(cloud, *c, top->top - top->band, 2.0 * noise_sigma, config.min_z_m);
    if (seen.widest_spread_m > kCurvedWall * kWallRange * noise_sigma) {
        return Error{ErrorCode::kInsufficientData,
                     fmt::format("one view cannot bound the object: a side it shows is curved "
                                 "(its readings spread over {:.0f} mm), so it is no box (more "
                                 "poses needed)",
                                 seen.widest_spread_m * 1e3)};
    }
    for (std::size_t axis = 0; axis < 2; ++axis) {
        const double hidden = std::sqrt(static_cast<double>(seen.hidden[axis]));
        c->sigma_m[axis] = std::hypot(c->sigma_m[axis], hidden * 2.0 * seen.reach_m / kNormal95);
    }
    // The height is the top's median; where part of the top stands higher (a strap: strapped
    // cartons read 2.1-2.7 mm low from one view with bounds of 1.8-2.2 mm), the object reaches
    // that high, and the bound carries it.
    c->sigma_m[2] = std::hypot(c->sigma_m[2], top->upper_level / kNormal95);
    c->cuboid = true;
    c->assumed = true;
    return c;
}

}  // namespace boxd::envelope
