#include "pipeline/fit/box_fit.h"

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/core/key_index.h"
#include "pipeline/fit/box_faces.h"
#include "pipeline/fit/face_choice.h"
#include "pipeline/fit/rounded_edges.h"

namespace boxd {

namespace {

using box_faces::BoxState;
using box_faces::EdgeSamples;
using box_faces::FaceNormal;
using box_faces::FitSides;
using box_faces::FitTop;

Status Bad(const std::string& field, const std::string& why) {
    return Error{ErrorCode::kInvalidConfig, "box_fit." + field + ": " + why};
}

// Returns the footprint seed: the minimal-area rectangle of the occupied footprint cells.
Result<BoxState> SeedFootprint(const Points& points, const BoxFitConfig& config) {
    const double inv = 1.0 / config.footprint_cell_m;
    KeyIndex index;
    std::vector<std::int64_t> cell_key;  // by dense index
    std::vector<int> count;
    for (const Eigen::Vector3f& p : points) {
        if (p.z() < config.footprint_min_z_m) continue;
        const auto ix = static_cast<std::int64_t>(std::floor(p.x() * inv));
        const auto iy = static_cast<std::int64_t>(std::floor(p.y() * inv));
        const std::int64_t key = (ix << 32) ^ (iy & 0xFFFFFFFF);
        const std::size_t c = index.Find(static_cast<std::uint64_t>(key));
        if (c == count.size()) {
            cell_key.push_back(key);
            count.push_back(0);
        }
        ++count[c];
    }
    std::vector<cv::Point2f> centres;
    for (std::size_t c = 0; c < count.size(); ++c) {
        if (count[c] < config.footprint_min_cell_points) continue;
        const auto ix = static_cast<double>(cell_key[c] >> 32);
        const auto iy = static_cast<double>(static_cast<std::int32_t>(cell_key[c] & 0xFFFFFFFF));
        centres.emplace_back(static_cast<float>((ix + 0.5) * config.footprint_cell_m),
                             static_cast<float>((iy + 0.5) * config.footprint_cell_m));
    }
    if (centres.size() < 3) {
        return Error{ErrorCode::kObjectTooSmall, "the object's footprint is too small to measure"};
    }
    // Order-independent input for minAreaRect: sort the centres (first-seen order is not).
    std::sort(centres.begin(), centres.end(), [](const cv::Point2f& a, const cv::Point2f& b) {
        return a.x < b.x || (a.x == b.x && a.y < b.y);
    });
    std::vector<cv::Point2f> hull;
    cv::convexHull(centres, hull);
    const cv::RotatedRect rect = cv::minAreaRect(hull);
    cv::Point2f corners[4];
    rect.points(corners);
    const Eigen::Vector2d c0(corners[0].x, corners[0].y), c1(corners[1].x, corners[1].y),
        c2(corners[2].x, corners[2].y);
    const Eigen::Vector2d e_u = c1 - c0, e_v = c2 - c1;
    BoxState s;
    s.yaw = std::atan2(e_u.y(), e_u.x());
    const Eigen::Vector2d center(rect.center.x, rect.center.y);
    const double half_u = 0.5 * e_u.norm(), half_v = 0.5 * e_v.norm();
    for (int f = 0; f < 4; ++f) {
        s.d[static_cast<std::size_t>(f)] =
            FaceNormal(s.yaw, f).dot(center) + (f < 2 ? half_u : half_v);
    }
    return s;
}
}  // namespace

Status BoxFitConfig::Validate() const {
    if (!(footprint_min_z_m >= 0.0)) return Bad("footprint_min_z_m", "must be >= 0");
    if (!(footprint_cell_m > 0.0005 && footprint_cell_m < 0.05)) {
        return Bad("footprint_cell_m", "must be in (0.0005, 0.05)");
    }
    if (footprint_min_cell_points < 1) return Bad("footprint_min_cell_points", "must be >= 1");
    if (!(seed_top_quantile > 0.5 && seed_top_quantile <= 1.0)) {
        return Bad("seed_top_quantile", "must be in (0.5, 1]");
    }
    if (!(initial_band_m > 0.0)) return Bad("initial_band_m", "must be > 0");
    if (!(min_band_m > 0.0 && min_band_m <= initial_band_m)) {
        return Bad("min_band_m", "must be in (0, initial_band_m]");
    }
    if (!(band_sigmas >= 1.0)) return Bad("band_sigmas", "must be >= 1");
    if (!(edge_margin_m >= 0.0)) return Bad("edge_margin_m", "must be >= 0");
    if (!(trim_sigmas >= 1.0)) return Bad("trim_sigmas", "must be >= 1");
    if (iterations < 1 || iterations > 50) return Bad("iterations", "must be in 1..50");
    if (min_face_points < 3) return Bad("min_face_points", "must be >= 3");
    if (threads < 1 || threads > 64) return Bad("threads", "must be in 1..64");
    return OkStatus();
}

Result<BoxFit> FitFootprintBox(const Points& points, const BoxFitConfig& config) {
    return FitFootprintBox(points, points, config);
}

namespace {

// The faces' fit as it iterates: the box, each face's band (sides, then the top's), the readings
// each face kept, and whether the top is read.
struct FaceFit {
    BoxState s;
    std::array<double, 4> band{};
    double top_band = 0.0;
    std::array<int, 5> counts{};
    bool top_observed = true;
};

// The height of the `quantile` of the seed's readings.
double SeedHeight(const Points& seed_points, double quantile) {
    std::vector<float> z(seed_points.size());
    for (std::size_t i = 0; i < seed_points.size(); ++i) z[i] = seed_points[i].z();
    const auto q = static_cast<long>(quantile * static_cast<double>(z.size() - 1));
    std::nth_element(z.begin(), z.begin() + q, z.end());
    return z[static_cast<std::size_t>(q)];
}

// Rounded edges reaching farther in than the margin: the faces fitted again clear of them (two
// passes). Returns the margin they were fitted with, 0 where the edges do not round off farther
// or the refit fails (the fit then stays as it was).
double RefitClearOfRounding(const Points& points, const BoxFitConfig& config,
                            const ReadingRays* by_ray, double margin, FaceFit& f) {
    const double smallest = std::min({f.s.d[0] + f.s.d[1], f.s.d[2] + f.s.d[3], f.s.height});
    const double rounded = RoundedEdgeMargin(
        EdgeSamples(points, config, by_ray, margin, f.band, f.top_band, f.top_observed, f.s),
        margin, 0.25 * smallest);
    if (rounded <= margin) return 0.0;
    spdlog::debug("box fit: the faces round off; margin {:.1f} -> {:.1f} mm", margin * 1e3,
                  rounded * 1e3);
    const FaceFit before = f;
    bool refitted = true;
    for (int it = 0; it < 2 && refitted; ++it) {
        if (f.top_observed && !FitTop(points, config, by_ray, rounded, f.top_band, f.s, f.counts)) {
            refitted = false;
        }
        if (refitted && !FitSides(points, config, by_ray, rounded, f.band, f.s, f.counts)) {
            refitted = false;
        }
    }
    if (refitted) return rounded;
    f = before;
    return 0.0;
}

// The box of the fitted faces.
BoxFit BoxOf(const FaceFit& f, double rounded_margin) {
    const BoxState& s = f.s;
    BoxFit fit;
    fit.rounded_margin_m = rounded_margin;
    fit.top_observed = f.top_observed;
    const double len_u = s.d[0] + s.d[1], len_v = s.d[2] + s.d[3];
    const double cu = 0.5 * (s.d[0] - s.d[1]), cv = 0.5 * (s.d[2] - s.d[3]);
    const Eigen::Vector2d nu = FaceNormal(s.yaw, 0), nv = FaceNormal(s.yaw, 2);
    fit.center_m = cu * nu + cv * nv;
    fit.length_m = std::max(len_u, len_v);
    fit.width_m = std::min(len_u, len_v);
    fit.length_axis = len_u >= len_v ? nu : nv;
    fit.height_m = s.height;
    fit.face_points = f.counts;
    fit.face_sigma_m =
        *std::max_element(s.sigma.begin(), s.sigma.begin() + (f.top_observed ? 5 : 4));
    return fit;
}

}  // namespace

Result<BoxFit> FitFootprintBox(const Points& seed_points, const Points& points,
                               const BoxFitConfig& config, const ReadingRays& rays) {
    const ReadingRays* by_ray = rays.Covers(points.size()) ? &rays : nullptr;
    if (seed_points.size() < 10 || points.size() < 10) {
        return Error{ErrorCode::kObjectTooSmall, "too few object points"};
    }
    auto seeded = SeedFootprint(seed_points, config);
    if (!seeded) return seeded.error();
    FaceFit f;
    f.s = *seeded;
    f.s.height = SeedHeight(seed_points, config.seed_top_quantile);
    const BoxState& s = f.s;
    const double min_side = std::min(s.d[0] + s.d[1], s.d[2] + s.d[3]);
    const double margin = EdgeMargin(config.edge_margin_m, std::min(min_side, s.height));
    if (min_side < 2.0 * margin + 0.01 || s.height < 2.0 * margin + 0.005) {
        return Error{ErrorCode::kObjectTooSmall, "the object is too small to measure"};
    }
    f.band.fill(config.initial_band_m);
    f.top_band = config.initial_band_m;
    // A top seen only at grazing incidence (a tall box, a camera little above it) has too few
    // readings to fit: the sides are fitted all the same, at the height of the highest readings,
    // and the height is left to the enclosing cuboid (where the side faces end).
    auto fit_top = [&] {
        if (f.top_observed && !FitTop(points, config, by_ray, margin, f.top_band, f.s, f.counts)) {
            f.top_observed = false;
        }
    };
    for (int it = 0; it < config.iterations; ++it) {
        fit_top();
        if (!FitSides(points, config, by_ray, margin, f.band, f.s, f.counts)) {
            return Error{ErrorCode::kInsufficientData,
                         "a side face of the object is not observed well enough"};
        }
        for (std::size_t k = 0; k < 4; ++k) {
            f.band[k] = std::clamp(config.band_sigmas * s.sigma[k], config.min_band_m,
                                   config.initial_band_m);
        }
        f.top_band =
            std::clamp(config.band_sigmas * s.sigma[4], config.min_band_m, config.initial_band_m);
    }
    fit_top();
    const double rounded_margin = RefitClearOfRounding(points, config, by_ray, margin, f);
    return BoxOf(f, rounded_margin);
}

OrientedBox FitPcaBox(const Points& points) {
    OrientedBox box;
    if (points.empty()) return box;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : points) mean += p.head<2>().cast<double>();
    mean /= static_cast<double>(points.size());
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& p : points) {
        const Eigen::Vector2d d = p.head<2>().cast<double>() - mean;
        cov += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
    Eigen::Vector2d e1 = es.eigenvectors().col(1);  // major axis
    // A sign convention makes the axes deterministic: the major axis points to +x (or +y).
    if (e1.x() < 0.0 || (e1.x() == 0.0 && e1.y() < 0.0)) e1 = -e1;
    const Eigen::Vector2d e2(-e1.y(), e1.x());
    double lo1 = 1e9, hi1 = -1e9, lo2 = 1e9, hi2 = -1e9, hz = 0.0;
    for (const auto& p : points) {
        const Eigen::Vector2d d = p.head<2>().cast<double>();
        lo1 = std::min(lo1, e1.dot(d));
        hi1 = std::max(hi1, e1.dot(d));
        lo2 = std::min(lo2, e2.dot(d));
        hi2 = std::max(hi2, e2.dot(d));
        hz = std::max(hz, static_cast<double>(p.z()));
    }
    const Eigen::Vector2d c = 0.5 * (lo1 + hi1) * e1 + 0.5 * (lo2 + hi2) * e2;
    box.extent_m = {hi1 - lo1, hi2 - lo2, hz};
    box.volume_m3 = box.extent_m[0] * box.extent_m[1] * box.extent_m[2];
    box.center_m = {c.x(), c.y(), 0.5 * hz};
    box.axes = {{{e1.x(), e1.y(), 0.0}, {e2.x(), e2.y(), 0.0}, {0.0, 0.0, 1.0}}};
    return box;
}

double DistanceToBoxSurface(const BoxFit& box, const Eigen::Vector3f& p) {
    const Eigen::Vector2d a = box.length_axis, b(-a.y(), a.x());
    const Eigen::Vector2d d = p.head<2>().cast<double>() - box.center_m;
    // Coordinates relative to the box centre; the box spans [-hl, hl] x [-hw, hw] x [0, h].
    const double u = a.dot(d), v = b.dot(d), z = p.z();
    const double hl = 0.5 * box.length_m, hw = 0.5 * box.width_m, h = box.height_m;
    const double ou = std::abs(u) - hl, ov = std::abs(v) - hw, oz = std::max(z - h, -z);
    if (ou > 0.0 || ov > 0.0 || oz > 0.0) {
        return std::sqrt(std::pow(std::max(ou, 0.0), 2) + std::pow(std::max(ov, 0.0), 2) +
                         std::pow(std::max(oz, 0.0), 2));
    }
    // Inside: the nearest of the sides and the top (the bottom rests on the table, unseen).
    return std::min({-ou, -ov, h - z});
}

}  // namespace boxd
