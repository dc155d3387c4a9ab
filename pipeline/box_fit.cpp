#include "pipeline/box_fit.h"

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "pipeline/face_choice.h"
#include "pipeline/key_index.h"
#include "pipeline/median.h"
#include "pipeline/parallel_for.h"
#include "pipeline/rounded_edges.h"

namespace boxd {

namespace {

Status Bad(const std::string& field, const std::string& why) {
    return Error{ErrorCode::kInvalidConfig, "box_fit." + field + ": " + why};
}

// 1.4826 * the median absolute deviation from `center`: the standard deviation of normally
// distributed values about it.
double MadSigma(const std::vector<double>& values, double center) {
    std::vector<double> a(values.size());
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = std::abs(values[i] - center);
    return 1.4826 * Median(std::move(a));
}

// The same about the residuals' own median.
double RobustSigma(const std::vector<double>& residuals) {
    return MadSigma(residuals, Median(residuals));
}

// The box in its own footprint frame: u along `yaw`, v perpendicular, origin at the table.
struct BoxState {
    double yaw = 0.0;
    // Outward offsets of the side faces along +u, -u, +v, -v: face f is {p : n_f · p = d_f}.
    std::array<double, 4> d{};
    double height = 0.0;
    std::array<double, 5> sigma{};  // robust sigma per face (sides, top)
};

Eigen::Vector2d FaceNormal(double yaw, int face) {
    const double a = yaw + (face == 0 ? 0.0 : face == 1 ? M_PI : face == 2 ? M_PI / 2 : -M_PI / 2);
    return {std::cos(a), std::sin(a)};
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

struct FacePoint {
    int face;
    Eigen::Vector2d xy;
};

// One pass of the side-face fit: selects the points in each face's band (away from the edges),
// then solves the linearised least squares for a common yaw and the four offsets, trimming
// outliers once. Returns false when a face has too few points.
bool FitSides(const Points& points, const BoxFitConfig& config, const ReadingRays* rays,
              double margin, const std::array<double, 4>& band, BoxState& s,
              std::array<int, 5>& counts) {
    std::array<Eigen::Vector2d, 4> n;
    for (int f = 0; f < 4; ++f) n[static_cast<std::size_t>(f)] = FaceNormal(s.yaw, f);
    const double half_u = 0.5 * (s.d[0] + s.d[1]), half_v = 0.5 * (s.d[2] + s.d[3]);
    const double cu = 0.5 * (s.d[0] - s.d[1]), cv = 0.5 * (s.d[2] - s.d[3]);
    const FaceChoice choice(rays, margin);
    const double m = choice.margin(), gate = choice.gate();
    const std::vector<FacePoint> sel = ParallelCollect<FacePoint>(
        points.size(), config.threads,
        [&](std::size_t begin, std::size_t end, std::vector<FacePoint>& out) {
            for (std::size_t i = begin; i < end; ++i) {
                const Eigen::Vector3f& p3 = points[i];
                if (p3.z() < gate || p3.z() > s.height - gate) continue;
                const Eigen::Vector2d p = p3.head<2>().cast<double>();
                for (int f = 0; f < 4; ++f) {
                    const auto k = static_cast<std::size_t>(f);
                    const double r = n[k].dot(p) - s.d[k];
                    if (std::abs(r) > band[k]) continue;
                    const Eigen::Vector2d& across = f < 2 ? n[2] : n[0];
                    const double mid = f < 2 ? cv : cu, half = f < 2 ? half_v : half_u;
                    if (std::abs(across.dot(p) - mid) > half - gate) continue;
                    const auto x =
                        choice.Judged(i, p3, Eigen::Vector3d(n[k].x(), n[k].y(), 0.0), s.d[k]);
                    if (!x || x->z() < m || x->z() > s.height - m ||
                        std::abs(across.dot(x->head<2>()) - mid) > half - m) {
                        continue;
                    }
                    out.push_back({f, p});
                }
            }
        });
    auto solve = [&](const std::vector<char>& use, std::array<int, 5>& cnt) {
        // Unknowns: dyaw, dd0..dd3. r + (n'·p) dyaw - dd_f = 0.
        Eigen::Matrix<double, 5, 5> h = Eigen::Matrix<double, 5, 5>::Zero();
        Eigen::Matrix<double, 5, 1> g = Eigen::Matrix<double, 5, 1>::Zero();
        cnt.fill(0);
        for (std::size_t i = 0; i < sel.size(); ++i) {
            if (!use[i]) continue;
            const auto k = static_cast<std::size_t>(sel[i].face);
            const Eigen::Vector2d nd(-n[k].y(), n[k].x());
            const double r = n[k].dot(sel[i].xy) - s.d[k];
            // The Jacobian row has two entries, j0 and -1 at 1 + k: only the terms they touch
            // (h is symmetric; its lower triangle is all ldlt reads).
            const double j0 = nd.dot(sel[i].xy);
            const long f = 1 + static_cast<long>(k);
            h(0, 0) += j0 * j0;
            h(f, 0) -= j0;
            h(f, f) += 1.0;
            g(0) += j0 * r;
            g(f) -= r;
            ++cnt[k];
        }
        h.diagonal().array() += 1e-12;
        return Eigen::Matrix<double, 5, 1>(h.ldlt().solve(-g));
    };
    std::vector<char> use(sel.size(), 1);
    std::array<int, 5> cnt{};
    Eigen::Matrix<double, 5, 1> delta = solve(use, cnt);
    // Trim per face with the robust sigma of the residuals after the first solve.
    std::array<std::vector<double>, 4> res;
    std::vector<double> r_all(sel.size());
    for (std::size_t i = 0; i < sel.size(); ++i) {
        const auto k = static_cast<std::size_t>(sel[i].face);
        const Eigen::Vector2d nd(-n[k].y(), n[k].x());
        r_all[i] = n[k].dot(sel[i].xy) - s.d[k] + nd.dot(sel[i].xy) * delta(0) - delta(1 + k);
        res[k].push_back(r_all[i]);
    }
    std::array<double, 4> sig{};
    // Four medians of tens of thousands of residuals each: the bulk of the fit's time.
    ParallelFor(4, config.threads, [&](int f) {
        const auto k = static_cast<std::size_t>(f);
        sig[k] = std::max(RobustSigma(res[k]), 1e-4);
    });
    for (std::size_t i = 0; i < sel.size(); ++i) {
        const auto k = static_cast<std::size_t>(sel[i].face);
        use[i] = std::abs(r_all[i]) <= config.trim_sigmas * sig[k];
    }
    delta = solve(use, cnt);
    for (std::size_t k = 0; k < 4; ++k) {
        counts[k] = cnt[k];
        s.sigma[k] = sig[k];
    }
    if (*std::min_element(cnt.begin(), cnt.begin() + 4) < config.min_face_points) return false;
    // The offsets are relative to the old yaw's normals; the normals rotate with the yaw, which
    // is what the linearisation assumed, so the offsets apply as they are.
    s.yaw += delta(0);
    for (std::size_t k = 0; k < 4; ++k) s.d[k] += delta(1 + static_cast<long>(k));
    return true;
}

// Top face: trimmed mean height of the points inside the footprint (away from its edges) and in
// the band around the current height estimate.
bool FitTop(const Points& points, const BoxFitConfig& config, const ReadingRays* rays,
            double margin, double band, BoxState& s, std::array<int, 5>& counts) {
    const Eigen::Vector2d nu = FaceNormal(s.yaw, 0), nv = FaceNormal(s.yaw, 2);
    const double half_u = 0.5 * (s.d[0] + s.d[1]), half_v = 0.5 * (s.d[2] + s.d[3]);
    const double cu = 0.5 * (s.d[0] - s.d[1]), cv = 0.5 * (s.d[2] - s.d[3]);
    const FaceChoice choice(rays, margin);
    const double m = choice.margin(), gate = choice.gate();
    auto inside = [&](const Eigen::Vector2d& p, double inset) {
        return std::abs(nu.dot(p) - cu) <= half_u - inset &&
               std::abs(nv.dot(p) - cv) <= half_v - inset;
    };
    const std::vector<double> z = ParallelCollect<double>(
        points.size(), config.threads,
        [&](std::size_t begin, std::size_t end, std::vector<double>& out) {
            for (std::size_t i = begin; i < end; ++i) {
                const Eigen::Vector3f& p3 = points[i];
                if (std::abs(p3.z() - s.height) > band) continue;
                if (!inside(p3.head<2>().cast<double>(), gate)) continue;
                const auto x = choice.Judged(i, p3, Eigen::Vector3d::UnitZ(), s.height);
                if (!x || !inside(x->head<2>(), m)) continue;
                out.push_back(p3.z());
            }
        });
    if (static_cast<int>(z.size()) < config.min_face_points) {
        counts[4] = static_cast<int>(z.size());
        return false;
    }
    const double med = Median(z);
    const double sig = std::max(MadSigma(z, med), 1e-4);
    double sum = 0.0;
    int n = 0;
    for (double v : z) {
        if (std::abs(v - med) <= config.trim_sigmas * sig) {
            sum += v;
            ++n;
        }
    }
    counts[4] = n;
    if (n < config.min_face_points) return false;
    s.height = sum / n;
    s.sigma[4] = sig;
    return true;
}

// Every face reading of the fitted box `s` with how far inside its face's nearest edge it lies
// (read where its ray meets the face, as the margins are) and how far out of the face it
// stands, for the readings beyond `margin`: outwards within each face's band and trim, inwards
// within the first pass's band (a rounding falls millimetres inside the face: 14 mm at the
// 15 mm margin for a radius of 50 mm) and no deeper than they lie inside the edge, as deep as
// any circular rounding reaches there (at e inside, r - sqrt(r² - (r - e)²) <= e): deeper ones
// are another face's, seen past the edge.
std::vector<EdgeSample> EdgeSamples(const Points& points, const BoxFitConfig& config,
                                    const ReadingRays* rays, double margin,
                                    const std::array<double, 4>& band, double top_band,
                                    bool top_observed, const BoxState& s) {
    std::array<Eigen::Vector2d, 4> n;
    for (int f = 0; f < 4; ++f) n[static_cast<std::size_t>(f)] = FaceNormal(s.yaw, f);
    const double half_u = 0.5 * (s.d[0] + s.d[1]), half_v = 0.5 * (s.d[2] + s.d[3]);
    const double cu = 0.5 * (s.d[0] - s.d[1]), cv = 0.5 * (s.d[2] - s.d[3]);
    const FaceChoice choice(rays, margin);
    return ParallelCollect<EdgeSample>(
        points.size(), config.threads,
        [&](std::size_t begin, std::size_t end, std::vector<EdgeSample>& out) {
            for (std::size_t i = begin; i < end; ++i) {
                const Eigen::Vector3f& p3 = points[i];
                const Eigen::Vector2d p = p3.head<2>().cast<double>();
                for (int f = 0; f < 4; ++f) {
                    const auto k = static_cast<std::size_t>(f);
                    const double r = n[k].dot(p) - s.d[k];
                    if (r > std::min(band[k], config.trim_sigmas * s.sigma[k]) ||
                        r < -config.initial_band_m) {
                        continue;
                    }
                    const auto x =
                        choice.Judged(i, p3, Eigen::Vector3d(n[k].x(), n[k].y(), 0.0), s.d[k]);
                    if (!x) continue;
                    const Eigen::Vector2d& across = f < 2 ? n[2] : n[0];
                    const double mid = f < 2 ? cv : cu, half = f < 2 ? half_v : half_u;
                    const double inside =
                        std::min({x->z(), s.height - x->z(),
                                  half - std::abs(across.dot(x->head<2>()) - mid)});
                    if (inside >= margin && -r <= inside) out.push_back({inside, r});
                }
                if (!top_observed) continue;
                const double r = p3.z() - s.height;
                if (r > std::min(top_band, config.trim_sigmas * s.sigma[4]) ||
                    r < -config.initial_band_m) {
                    continue;
                }
                const auto x = choice.Judged(i, p3, Eigen::Vector3d::UnitZ(), s.height);
                if (!x) continue;
                const double inside = std::min(half_u - std::abs(n[0].dot(x->head<2>()) - cu),
                                               half_v - std::abs(n[2].dot(x->head<2>()) - cv));
                if (inside >= margin && -r <= inside) out.push_back({inside, r});
            }
        });
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

Result<BoxFit> FitFootprintBox(const Points& seed_points, const Points& points,
                               const BoxFitConfig& config, const ReadingRays& rays) {
    const ReadingRays* by_ray = rays.Covers(points.size()) ? &rays : nullptr;
    if (seed_points.size() < 10 || points.size() < 10) {
        return Error{ErrorCode::kObjectTooSmall, "too few object points"};
    }
    auto seeded = SeedFootprint(seed_points, config);
    if (!seeded) return seeded.error();
    BoxState s = *seeded;
    {
        std::vector<float> z(seed_points.size());
        for (std::size_t i = 0; i < seed_points.size(); ++i) z[i] = seed_points[i].z();
        const auto q =
            static_cast<long>(config.seed_top_quantile * static_cast<double>(z.size() - 1));
        std::nth_element(z.begin(), z.begin() + q, z.end());
        s.height = z[static_cast<std::size_t>(q)];
    }
    const double min_side = std::min(s.d[0] + s.d[1], s.d[2] + s.d[3]);
    const double margin = EdgeMargin(config.edge_margin_m, std::min(min_side, s.height));
    double rounded_margin = 0.0;
    if (min_side < 2.0 * margin + 0.01 || s.height < 2.0 * margin + 0.005) {
        return Error{ErrorCode::kObjectTooSmall, "the object is too small to measure"};
    }
    std::array<double, 4> band;
    band.fill(config.initial_band_m);
    double top_band = config.initial_band_m;
    std::array<int, 5> counts{};
    // A top seen only at grazing incidence (a tall box, a camera little above it) has too few
    // readings to fit: the sides are fitted all the same, at the height of the highest readings,
    // and the height is left to the enclosing cuboid (where the side faces end).
    bool top_observed = true;
    for (int it = 0; it < config.iterations; ++it) {
        if (top_observed && !FitTop(points, config, by_ray, margin, top_band, s, counts)) {
            top_observed = false;
        }
        if (!FitSides(points, config, by_ray, margin, band, s, counts)) {
            return Error{ErrorCode::kInsufficientData,
                         "a side face of the object is not observed well enough"};
        }
        for (std::size_t k = 0; k < 4; ++k) {
            band[k] = std::clamp(config.band_sigmas * s.sigma[k], config.min_band_m,
                                 config.initial_band_m);
        }
        top_band =
            std::clamp(config.band_sigmas * s.sigma[4], config.min_band_m, config.initial_band_m);
    }
    if (top_observed && !FitTop(points, config, by_ray, margin, top_band, s, counts)) {
        top_observed = false;
    }
    // Rounded edges reaching farther in than the margin: fitted again clear of them.
    const double smallest = std::min({s.d[0] + s.d[1], s.d[2] + s.d[3], s.height});
    const double rounded = RoundedEdgeMargin(
        EdgeSamples(points, config, by_ray, margin, band, top_band, top_observed, s), margin,
        0.25 * smallest);
    if (rounded > margin) {
        spdlog::debug("box fit: the faces round off; margin {:.1f} -> {:.1f} mm", margin * 1e3,
                      rounded * 1e3);
        const BoxState before = s;
        const std::array<int, 5> counts_before = counts;
        bool refitted = true;
        for (int it = 0; it < 2 && refitted; ++it) {
            if (top_observed && !FitTop(points, config, by_ray, rounded, top_band, s, counts)) {
                refitted = false;
            }
            if (refitted && !FitSides(points, config, by_ray, rounded, band, s, counts)) {
                refitted = false;
            }
        }
        if (refitted) {
            rounded_margin = rounded;
        } else {
            s = before;
            counts = counts_before;
        }
    }
    BoxFit fit;
    fit.rounded_margin_m = rounded_margin;
    fit.top_observed = top_observed;
    const double len_u = s.d[0] + s.d[1], len_v = s.d[2] + s.d[3];
    const double cu = 0.5 * (s.d[0] - s.d[1]), cv = 0.5 * (s.d[2] - s.d[3]);
    const Eigen::Vector2d nu = FaceNormal(s.yaw, 0), nv = FaceNormal(s.yaw, 2);
    fit.center_m = cu * nu + cv * nv;
    fit.length_m = std::max(len_u, len_v);
    fit.width_m = std::min(len_u, len_v);
    fit.length_axis = len_u >= len_v ? nu : nv;
    fit.height_m = s.height;
    fit.face_points = counts;
    fit.face_sigma_m = *std::max_element(s.sigma.begin(), s.sigma.begin() + (top_observed ? 5 : 4));
    return fit;
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
