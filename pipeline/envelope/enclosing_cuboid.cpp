#include "pipeline/envelope/enclosing_cuboid.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "pipeline/envelope/cuboid_foot.h"
#include "pipeline/envelope/face_envelope.h"
#include "pipeline/envelope/single_view_cuboid.h"
#include "pipeline/envelope/support_envelope.h"
#include "pipeline/envelope/surface_cells.h"

namespace boxd {

namespace {

// The convex hull of the footprint over the smallest rectangle round that hull: 1 for a box,
// pi/4 for a tube standing, 7/8 for an L of a quarter cut away. Noise scatters single readings a
// few sigma beyond the surface, and a hull of readings would grow by that all round; the hull is
// therefore taken of the centres of the footprint cells that hold several readings (scattered
// readings rarely share a cell). The rectangle is the hull's own, not the face fit's: cut into
// the same cells, the two grow and shrink together with the cells' placing, and a tube's face
// fit stands at its flanks' mean planes, inside the circle (an 80 mm tube's at 77 mm, whose
// rectangle the circle's cells then filled to 1). The cells are fill_cell_m, or finer for a small
// footprint, so that fill_cells_across of them span its width: a box's hull loses about a cell's
// share of its corners, 2-3% at 16 cells, where a circle's stays near pi/4.
double FillRatio(const envelope::Surface& surface, const EnclosingCuboid& c,
                 const EnvelopeConfig& config) {
    const double cell = std::min(config.fill_cell_m, c.width_m / config.fill_cells_across);
    if (!(cell > 0.0)) return 0.0;
    std::vector<Eigen::Vector2d> footprint;
    footprint.reserve(surface.points.size());
    for (const Eigen::Vector3f& p : surface.points) footprint.push_back(p.head<2>().cast<double>());
    std::vector<cv::Point2f> centres;
    for (const auto& [key, n] : envelope::CountFootprintCells(footprint, cell)) {
        if (n < config.fill_cell_points) continue;
        centres.emplace_back(static_cast<float>((key.first + 0.5) * cell),
                             static_cast<float>((key.second + 0.5) * cell));
    }
    if (centres.size() < 3) return 0.0;
    std::vector<cv::Point2f> hull;
    cv::convexHull(centres, hull);
    const double rectangle = cv::minAreaRect(hull).size.area();
    if (!(rectangle > 0.0)) return 0.0;
    return std::min(1.0, cv::contourArea(hull) / rectangle);
}

// The share of the footprint's readings (in cells of fill_cell_m holding at least
// fill_cell_points) that stand in a cell whose highest reading lies within the top band below
// the height. Each cell counts by its readings, not as one: a cell beside a wall that holds only
// the few readings the noise scatters off it has its highest anywhere up the wall, and tells
// nothing about the top, while a surface below the top band (a lying tube's flank, the carton
// under an open flap, a bag's sides) fills its cells with readings. Counted alike, the scattered
// cells round a 0.1 x 0.1 x 0.6 m box whose top was seen at 80 degrees (its inside empty)
// made a sixth of its cells and read it irregular (0.84); by readings it reads 1.00, the
// suite's boxes and parcels 0.99-1.00, its lying tubes 0.58-0.64, bags 0.43-0.73, open flaps
// 0.12-0.36.
double TopCover(const envelope::Surface& surface, double height, double sigma,
                const EnvelopeConfig& config) {
    const double cell = config.fill_cell_m;
    std::map<std::pair<int, int>, std::pair<int, float>> cells;  // readings, highest z
    for (const Eigen::Vector3f& p : surface.points) {
        auto& c = cells[{static_cast<int>(std::floor(p.x() / cell)),
                         static_cast<int>(std::floor(p.y() / cell))}];
        ++c.first;
        c.second = std::max(c.second, p.z());
    }
    const double floor = height - std::max(config.top_band * height, config.layer_sigmas * sigma);
    long readings = 0, top = 0;
    for (const auto& [key, c] : cells) {
        if (c.first < config.fill_cell_points) continue;
        readings += c.first;
        top += c.second >= floor ? c.first : 0;
    }
    return readings > 0 ? static_cast<double>(top) / static_cast<double>(readings) : 0.0;
}

}  // namespace

Status EnvelopeConfig::Validate() const {
    auto bad = [](const std::string& f, const std::string& why) -> Status {
        return Error{ErrorCode::kInvalidConfig, "envelope." + f + ": " + why};
    };
    if (!(cell_along_m > 0.0 && cell_along_m < 0.2)) return bad("cell_along_m", "in (0, 0.2)");
    if (!(cell_height_m > 0.0 && cell_height_m < 0.5)) return bad("cell_height_m", "in (0, 0.5)");
    if (min_cell_points < 3) return bad("min_cell_points", "must be >= 3");
    if (!(false_alarm > 0.0 && false_alarm < 0.5)) return bad("false_alarm", "in (0, 0.5)");
    if (!(edge_margin_m >= 0.0)) return bad("edge_margin_m", "must be >= 0");
    if (!(inward_band_sigmas > 0.0)) return bad("inward_band_sigmas", "must be > 0");
    if (!(outward_band_m > 0.0)) return bad("outward_band_m", "must be > 0");
    if (directions < 18) return bad("directions", "must be >= 18");
    if (max_points < 1000) return bad("max_points", "must be >= 1000");
    if (shape_points < 1000) return bad("shape_points", "must be >= 1000");
    if (threads < 1 || threads > 64) return bad("threads", "must be in 1..64");
    if (!(layer_sigmas > 0.0)) return bad("layer_sigmas", "must be > 0");
    if (!(min_fill > 0.0 && min_fill <= 1.0)) return bad("min_fill", "in (0, 1]");
    if (!(fill_cell_m > 0.0 && fill_cell_m < 0.05)) return bad("fill_cell_m", "in (0, 0.05)");
    if (!(fill_cells_across >= 4.0)) return bad("fill_cells_across", "must be >= 4");
    if (fill_cell_points < 1) return bad("fill_cell_points", "must be >= 1");
    if (!(max_relative_excess > 0.0)) return bad("max_relative_excess", "must be > 0");
    if (!(top_band > 0.0 && top_band < 1.0)) return bad("top_band", "in (0, 1)");
    if (!(min_top_cover > 0.0 && min_top_cover <= 1.0)) return bad("min_top_cover", "in (0, 1]");
    if (!(max_view_spread_rmse > 0.0)) return bad("max_view_spread_rmse", "must be > 0");
    if (!(max_incidence_deg > 0.0 && max_incidence_deg < 90.0)) {
        return bad("max_incidence_deg", "must be in (0, 90)");
    }
    if (!(narrowest_kept_m >= 0.0 && narrowest_kept_m < 0.1)) {
        return bad("narrowest_kept_m", "must be in [0, 0.1)");
    }
    return OkStatus();
}

namespace {

// What the face fits' cuboid is read from beside the fused cloud: its surface above the table
// (the support function's and a grazing top's subsample, and the shape figures'), the readings'
// noise, how closely the views agree.
struct FaceInputs {
    const envelope::Surface& surface;
    const envelope::Surface& shape;
    double sigma, height_sigma, agreement_m, noise_sigma_m;
};

void LogFaces(const std::array<envelope::FaceResult, 5>& faces, const EnclosingCuboid& c) {
    spdlog::debug(
        "envelope: face excess {:.2f} {:.2f} {:.2f} {:.2f} top {:.2f} mm (cell se {:.2f} {:.2f} "
        "{:.2f} {:.2f} {:.2f}), plane se {:.2f} {:.2f} {:.2f} {:.2f} {:.2f} mm, fill {:.3f}, "
        "top cover {:.3f}",
        faces[0].excess_m * 1e3, faces[1].excess_m * 1e3, faces[2].excess_m * 1e3,
        faces[3].excess_m * 1e3, faces[4].excess_m * 1e3, faces[0].excess_se_m * 1e3,
        faces[1].excess_se_m * 1e3, faces[2].excess_se_m * 1e3, faces[3].excess_se_m * 1e3,
        faces[4].excess_se_m * 1e3, faces[0].offset_se_m * 1e3, faces[1].offset_se_m * 1e3,
        faces[2].offset_se_m * 1e3, faces[3].offset_se_m * 1e3, faces[4].offset_se_m * 1e3, c.fill,
        c.top_cover);
}

// Returns the cuboid of the face fit `fit`: its faces moved out by what stands out of their
// planes, its sides `lu` along the fit's length axis and `lv` across it; `cuboid` where its
// faces are flat, at right angles and fill the rectangle.
EnclosingCuboid FaceFitCuboid(const FusedCloud& cloud, const BoxFit& fit, int views,
                              const FaceInputs& in, const EnvelopeConfig& config, double* lu,
                              double* lv) {
    const std::array<envelope::FaceResult, 5> faces =
        envelope::FaceEnvelopes(cloud, fit, views, config);
    EnclosingCuboid c;
    for (std::size_t f = 0; f < 5; ++f) c.excess_m[f] = faces[f].excess_m;
    const Eigen::Vector2d a = fit.length_axis, b(-a.y(), a.x());
    *lu = fit.length_m + faces[0].excess_m + faces[1].excess_m;
    *lv = fit.width_m + faces[2].excess_m + faces[3].excess_m;
    c.center_m = fit.center_m + 0.5 * (faces[0].excess_m - faces[1].excess_m) * a +
                 0.5 * (faces[2].excess_m - faces[3].excess_m) * b;
    c.length_m = std::max(*lu, *lv);
    c.width_m = std::min(*lu, *lv);
    c.length_axis = *lu >= *lv ? a : b;
    c.height_m = fit.height_m + faces[4].excess_m;
    double top_se = 0.0;
    if (!fit.top_observed) {
        // No top face to fit: the height is where the side faces end.
        c.height_m = envelope::TopBound(in.surface.points, in.sigma, in.height_sigma,
                                        in.surface.radius, config, &top_se, in.surface.view);
    }
    // Each side's excess against the box size across it: the sides against the footprint's
    // other dimension... the face's own span is what a bulge is measured against.
    const std::array<double, 5> span = {fit.width_m, fit.width_m, fit.length_m, fit.length_m,
                                        std::min(fit.length_m, fit.width_m)};
    c.flatness = 0.0;
    for (std::size_t f = 0; f < 5; ++f) {
        c.max_relative_excess = std::max(c.max_relative_excess, faces[f].excess_m / span[f]);
        // A face not told (NaN) leaves the whole not told.
        c.flatness = std::isnan(faces[f].flatness) || std::isnan(c.flatness)
                         ? std::numeric_limits<double>::quiet_NaN()
                         : std::max(c.flatness, faces[f].flatness);
    }
    // A face's position: the spread of its offset over the views, and when it stands out, the
    // cell that says how far.
    auto face_sigma = [&faces](std::size_t f) {
        return std::hypot(faces[f].offset_se_m, faces[f].excess_se_m);
    };
    const double s_u = std::hypot(face_sigma(0), face_sigma(1));
    const double s_v = std::hypot(face_sigma(2), face_sigma(3));
    c.sigma_m = {*lu >= *lv ? s_u : s_v, *lu >= *lv ? s_v : s_u,
                 fit.top_observed ? face_sigma(4) : top_se};
    c.fill = FillRatio(in.shape, c, config);
    c.top_cover = TopCover(in.shape, c.height_m, in.sigma, config);
    // A flat face stands where every view sees it, up to the views' registration; a curved
    // "face" (a tube's side) stands where each view's tangent is.
    double spread = 0.0;
    for (const envelope::FaceResult& f : faces) spread = std::max(spread, f.view_spread_m);
    c.cuboid =
        c.fill >= config.min_fill && c.top_cover >= config.min_top_cover &&
        c.max_relative_excess <= config.max_relative_excess &&
        spread <= config.max_view_spread_rmse * std::max(in.agreement_m, in.noise_sigma_m / 4);
    LogFaces(faces, c);
    // Flat faces at right angles, but a side that keeps sloping outward down to the table stands
    // widest where the face fit does not read it (its planes sit at their mean height).
    if (c.cuboid) {
        c.cuboid =
            envelope::SideLeaningOut(in.surface, fit, *lu, *lv, c.center_m,
                                     {face_sigma(0), face_sigma(1), face_sigma(2), face_sigma(3)},
                                     in.sigma, config) < 0;
    }
    return c;
}

}  // namespace

Result<EnclosingCuboid> FitEnclosingCuboid(const FusedCloud& cloud, const Result<BoxFit>& box,
                                           int views, double agreement_m, double noise_sigma_m,
                                           const Eigen::Vector3d& camera_m,
                                           const EnvelopeConfig& config) {
    // The outer layer of a cell column is the sensor's noise deep: the noise of the table top
    // about its plane, seen at about the object's distance.
    const double sigma = std::max(noise_sigma_m, 0.0005);
    if (views == 1) return envelope::SingleViewCuboid(cloud, sigma, config);
    // The subsamples of the surface above the table: what the support function and a grazing
    // top's height read, and what the shape's figures (fill, top cover) read.
    const envelope::Surface surface = envelope::SurfaceAbove(cloud, config.max_points, config);
    const envelope::Surface shape =
        envelope::SurfaceAbove(cloud, config.shape_points, config, false);
    // Where no view saw a top (the box fit found too few readings on one), the top's cells hold
    // walls' ends only, spread up the walls with their rays' vertical share of the noise (a
    // fifth of the table's at a grazing top). A top some view saw has rims beside it, read with
    // the noise of a surface facing up.
    const double height_sigma = box && !box->top_observed
                                    ? envelope::HeightNoiseSigma(sigma, camera_m, surface.top)
                                    : sigma;
    spdlog::debug("envelope: the readings' noise {:.3f} mm, in the top's height {:.3f} mm",
                  sigma * 1e3, height_sigma * 1e3);
    double face_excess = 0.0;  // the face fit's, when it was tried: a deciding figure either way
    if (box) {
        double lu = 0.0, lv = 0.0;
        EnclosingCuboid c = FaceFitCuboid(
            cloud, *box, views, {surface, shape, sigma, height_sigma, agreement_m, noise_sigma_m},
            config, &lu, &lv);
        if (c.cuboid) {
            if (Status st = envelope::AddUnseenFeet(surface, *box, lu, lv, sigma, config, &c);
                !st) {
                return st.error();
            }
            return c;
        }
        face_excess = c.max_relative_excess;
    }
    // No flat faces at right angles: the support function of the surface.
    auto c = envelope::EnvelopeCuboid(surface, sigma, height_sigma, config);
    if (!c) return c;
    c->cuboid = false;
    c->max_relative_excess = face_excess;
    c->fill = FillRatio(shape, *c, config);
    c->top_cover = TopCover(shape, c->height_m, sigma, config);
    return c;
}

}  // namespace boxd
