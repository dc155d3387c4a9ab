#include "pipeline/enclosing_cuboid.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace boxd {

namespace {

// Returns x with P(N(0,1) > x) = q (bisection on the complementary error function).
double UpperNormalQuantile(double q) {
    double lo = -10.0, hi = 10.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(mid / std::sqrt(2.0)) > q ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

struct CellStats {
    int n = 0;
    double sum = 0.0, sum_sq = 0.0;
    void Add(double x) {
        ++n;
        sum += x;
        sum_sq += x * x;
    }
    double Mean() const { return sum / n; }
    // Standard error of the mean (sample variance; at least a tenth of a millimetre of spread,
    // so that a cell of identical readings is not infinitely certain).
    double StdError() const {
        const double var = std::max(0.0, (sum_sq - sum * sum / n) / std::max(1, n - 1));
        return std::sqrt(std::max(var, 1e-8) / n);
    }
};

// The largest lower confidence bound over `cells` that hold enough points: how far outside the
// reference the surface certainly reaches. `se` is that cell's standard error, `judged` the
// number of cells judged. Returns -inf when no cell is judged.
double LargestBound(const std::vector<CellStats>& cells, const EnvelopeConfig& config, double* se,
                    int* judged) {
    int m = 0;
    for (const CellStats& c : cells) m += c.n >= config.min_cell_points ? 1 : 0;
    *judged = m;
    if (m == 0) return -INFINITY;
    const double k = UpperNormalQuantile(config.false_alarm / m);
    double best = -INFINITY;
    for (const CellStats& c : cells) {
        if (c.n < config.min_cell_points) continue;
        const double bound = c.Mean() - k * c.StdError();
        if (bound > best) {
            best = bound;
            *se = c.StdError();
        }
    }
    return best;
}

// A dense grid of cells over a rectangle of the (a, b) plane.
struct CellGrid {
    double a0, b0, da, db;
    int na, nb;
    std::vector<CellStats> cells;
    CellGrid(double a_lo, double a_hi, double b_lo, double b_hi, double cell_a, double cell_b)
        : a0(a_lo), b0(b_lo), da(cell_a), db(cell_b) {
        na = std::max(1, static_cast<int>(std::ceil((a_hi - a_lo) / cell_a)));
        nb = std::max(1, static_cast<int>(std::ceil((b_hi - b_lo) / cell_b)));
        cells.resize(static_cast<std::size_t>(na) * static_cast<std::size_t>(nb));
    }
    CellStats* At(double a, double b) {
        const int i = static_cast<int>(std::floor((a - a0) / da));
        const int j = static_cast<int>(std::floor((b - b0) / db));
        if (i < 0 || j < 0 || i >= na || j >= nb) return nullptr;
        return &cells[static_cast<std::size_t>(j) * static_cast<std::size_t>(na) +
                      static_cast<std::size_t>(i)];
    }
};

struct FaceResult {
    double excess_m = 0.0;
    double excess_se_m = 0.0;  // standard error of the cell that set the excess
    double offset_se_m = 0.0;  // standard error of the face plane's offset, from the views
};

// The excess of the 4 side faces and the top of `box` over their fitted planes, and the
// uncertainty of each plane from the spread of its offset between views.
std::array<FaceResult, 5> FaceEnvelopes(const FusedCloud& cloud, const BoxFit& box, int views,
                                        const EnvelopeConfig& config) {
    const Eigen::Vector2d a = box.length_axis, b(-a.y(), a.x());
    const double hl = box.length_m / 2.0, hw = box.width_m / 2.0, h = box.height_m;
    const double m = config.edge_margin_m;
    const double inward = std::max(config.inward_band_sigmas * box.face_sigma_m, 0.004);
    std::array<CellGrid, 5> grids = {
        CellGrid(-hw + m, hw - m, m, h - m, config.cell_along_m, config.cell_height_m),
        CellGrid(-hw + m, hw - m, m, h - m, config.cell_along_m, config.cell_height_m),
        CellGrid(-hl + m, hl - m, m, h - m, config.cell_along_m, config.cell_height_m),
        CellGrid(-hl + m, hl - m, m, h - m, config.cell_along_m, config.cell_height_m),
        CellGrid(-hl + m, hl - m, -hw + m, hw - m, config.cell_along_m, config.cell_along_m)};
    std::vector<std::array<CellStats, 5>> per_view(static_cast<std::size_t>(std::max(views, 1)));
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        const Eigen::Vector3f& p3 = cloud.points[i];
        const Eigen::Vector2d q = p3.head<2>().cast<double>() - box.center_m;
        const double u = a.dot(q), v = b.dot(q), z = p3.z();
        // Offset outside each face, and the face's own coordinates of the point.
        const std::array<double, 5> s = {u - hl, -u - hl, v - hw, -v - hw, z - h};
        const std::array<double, 5> ca = {v, -v, -u, u, u};
        const std::array<double, 5> cb = {z, z, z, z, v};
        for (std::size_t f = 0; f < 5; ++f) {
            if (s[f] < -inward || s[f] > config.outward_band_m) continue;
            if (CellStats* c = grids[f].At(ca[f], cb[f])) {
                c->Add(s[f]);
                const std::size_t view = i < cloud.view.size() ? cloud.view[i] : 0;
                if (s[f] <= inward && view < per_view.size()) per_view[view][f].Add(s[f]);
            }
        }
    }
    std::array<FaceResult, 5> out;
    for (std::size_t f = 0; f < 5; ++f) {
        double se = 0.0;
        int judged = 0;
        const double bound = LargestBound(grids[f].cells, config, &se, &judged);
        if (bound > 0.0) {
            out[f].excess_m = bound;
            out[f].excess_se_m = se;
        }
        // The plane's offset as each view sees it: their spread is the registration's and the
        // noise's contribution to the face's position.
        std::vector<double> offsets;
        int points = 0;
        for (const auto& v : per_view) {
            points += v[f].n;
            if (v[f].n >= 4 * config.min_cell_points) offsets.push_back(v[f].Mean());
        }
        if (offsets.size() >= 2) {
            double mean = 0.0, var = 0.0;
            for (double o : offsets) mean += o / offsets.size();
            for (double o : offsets) var += (o - mean) * (o - mean) / (offsets.size() - 1);
            out[f].offset_se_m = std::sqrt(var / offsets.size());
        } else {
            // One view: its noise over the face's cells (neighbouring pixels share their noise
            // through the lateral jitter, so cells, not points, are the independent samples).
            out[f].offset_se_m = box.face_sigma_m / std::sqrt(std::max(1, judged));
        }
        (void)points;
    }
    return out;
}

// The outer layer's largest bound in direction (cos φ, sin φ) and in the opposite one, over
// cells of (position across the direction, height).
struct Support {
    double forward = -INFINITY, backward = -INFINITY;
    double se_forward = 0.0, se_backward = 0.0;
};

Support SupportAlong(const std::vector<Eigen::Vector3f>& pts, double phi, double sigma,
                     double radius, double top, const EnvelopeConfig& config) {
    const Eigen::Vector2d u(std::cos(phi), std::sin(phi)), v(-u.y(), u.x());
    CellGrid front(-radius, radius, 0.0, top, config.cell_along_m, config.cell_height_m);
    CellGrid back = front;
    std::vector<double> max_s(front.cells.size(), -INFINITY), min_s(front.cells.size(), INFINITY);
    auto index = [&front](const CellStats* c) {
        return static_cast<std::size_t>(c - front.cells.data());
    };
    for (const Eigen::Vector3f& p : pts) {
        const Eigen::Vector2d q = p.head<2>().cast<double>();
        if (CellStats* c = front.At(v.dot(q), p.z())) {
            const std::size_t k = index(c);
            const double s = u.dot(q);
            max_s[k] = std::max(max_s[k], s);
            min_s[k] = std::min(min_s[k], s);
        }
    }
    const double layer = config.layer_sigmas * sigma;
    for (const Eigen::Vector3f& p : pts) {
        const Eigen::Vector2d q = p.head<2>().cast<double>();
        CellStats* c = front.At(v.dot(q), p.z());
        if (c == nullptr) continue;
        const std::size_t k = index(c);
        const double s = u.dot(q);
        if (s >= max_s[k] - layer) c->Add(s);
        if (s <= min_s[k] + layer) back.cells[k].Add(-s);
    }
    Support out;
    int judged = 0;
    out.forward = LargestBound(front.cells, config, &out.se_forward, &judged);
    out.backward = LargestBound(back.cells, config, &out.se_backward, &judged);
    return out;
}

// The height: the top's outer layer over (x, y) cells.
double TopBound(const std::vector<Eigen::Vector3f>& pts, double sigma, double radius,
                const EnvelopeConfig& config, double* se) {
    CellGrid grid(-radius, radius, -radius, radius, 2.0 * config.cell_along_m,
                  2.0 * config.cell_along_m);
    std::vector<double> max_z(grid.cells.size(), -INFINITY);
    for (const Eigen::Vector3f& p : pts) {
        if (CellStats* c = grid.At(p.x(), p.y())) {
            const auto k = static_cast<std::size_t>(c - grid.cells.data());
            max_z[k] = std::max(max_z[k], static_cast<double>(p.z()));
        }
    }
    for (const Eigen::Vector3f& p : pts) {
        if (CellStats* c = grid.At(p.x(), p.y())) {
            const auto k = static_cast<std::size_t>(c - grid.cells.data());
            if (p.z() >= max_z[k] - config.layer_sigmas * sigma) c->Add(p.z());
        }
    }
    int judged = 0;
    return LargestBound(grid.cells, config, se, &judged);
}

// The least-area footprint rectangle of the support function, and the height.
Result<EnclosingCuboid> EnvelopeCuboid(const FusedCloud& cloud, double sigma,
                                       const EnvelopeConfig& config) {
    std::vector<Eigen::Vector3f> pts;
    std::size_t above = 0;
    for (const Eigen::Vector3f& p : cloud.points) above += p.z() >= config.min_z_m ? 1 : 0;
    const std::size_t step = std::max<std::size_t>(1, above / config.max_points);
    double radius = 0.0, top = 0.0;
    std::size_t k = 0;
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() < config.min_z_m || (k++ % step) != 0) continue;
        pts.push_back(p);
        radius = std::max(radius, static_cast<double>(p.head<2>().norm()));
        top = std::max(top, static_cast<double>(p.z()));
    }
    if (pts.empty()) return Error{ErrorCode::kInsufficientData, "no surface above the table"};
    radius += 0.01;
    top += 0.01;
    auto width = [&](double phi, Support* s) {
        *s = SupportAlong(pts, phi, sigma, radius, top, config);
        return s->forward + s->backward;
    };
    // Every direction, then finer about the least area.
    const int n = config.directions;
    std::vector<Support> coarse(static_cast<std::size_t>(n));
    std::vector<double> w(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) w[i] = width(M_PI * i / n, &coarse[i]);
    int best = 0;
    for (int i = 1; i < n; ++i) {
        if (w[i] * w[(i + n / 2) % n] < w[best] * w[(best + n / 2) % n]) best = i;
    }
    double best_phi = M_PI * best / n, best_area = w[best] * w[(best + n / 2) % n];
    Support su = coarse[best], sv = coarse[(best + n / 2) % n];
    for (int j = -9; j <= 9; ++j) {
        const double phi = M_PI * best / n + j * (M_PI / n) / 10.0;
        Support a, b;
        const double area = width(phi, &a) * width(phi + M_PI / 2.0, &b);
        if (area < best_area) {
            best_area = area;
            best_phi = phi;
            su = a;
            sv = b;
        }
    }
    if (!std::isfinite(best_area)) {
        return Error{ErrorCode::kInsufficientData, "too few surface cells to bound the object"};
    }
    EnclosingCuboid c;
    const Eigen::Vector2d u(std::cos(best_phi), std::sin(best_phi)), v(-u.y(), u.x());
    const double lu = su.forward + su.backward, lv = sv.forward + sv.backward;
    c.center_m = 0.5 * (su.forward - su.backward) * u + 0.5 * (sv.forward - sv.backward) * v;
    c.length_m = std::max(lu, lv);
    c.width_m = std::min(lu, lv);
    c.length_axis = lu >= lv ? u : v;
    double se_top = 0.0;
    c.height_m = TopBound(pts, sigma, radius, config, &se_top);
    const double s_u = std::hypot(su.se_forward, su.se_backward);
    const double s_v = std::hypot(sv.se_forward, sv.se_backward);
    c.sigma_m = {lu >= lv ? s_u : s_v, lu >= lv ? s_v : s_u, se_top};
    return c;
}

// Footprint cells of `cloud` inside the rectangle of `c`, over the rectangle's area.
double FillRatio(const FusedCloud& cloud, const EnclosingCuboid& c, const EnvelopeConfig& config) {
    const Eigen::Vector2d a = c.length_axis, b(-a.y(), a.x());
    CellGrid grid(-c.length_m / 2.0, c.length_m / 2.0, -c.width_m / 2.0, c.width_m / 2.0,
                  config.footprint_cell_m, config.footprint_cell_m);
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() < config.min_z_m) continue;
        const Eigen::Vector2d q = p.head<2>().cast<double>() - c.center_m;
        if (CellStats* cell = grid.At(a.dot(q), b.dot(q))) cell->Add(0.0);
    }
    int occupied = 0;
    for (const CellStats& cell : grid.cells) occupied += cell.n >= 2 ? 1 : 0;
    return static_cast<double>(occupied) / static_cast<double>(grid.cells.size());
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
    if (!(layer_sigmas > 0.0)) return bad("layer_sigmas", "must be > 0");
    if (!(footprint_cell_m > 0.0)) return bad("footprint_cell_m", "must be > 0");
    if (!(min_fill > 0.0 && min_fill <= 1.0)) return bad("min_fill", "in (0, 1]");
    if (!(max_relative_excess > 0.0)) return bad("max_relative_excess", "must be > 0");
    return OkStatus();
}

Result<EnclosingCuboid> FitEnclosingCuboid(const FusedCloud& cloud, const Result<BoxFit>& box,
                                           int views, const EnvelopeConfig& config) {
    if (box) {
        const BoxFit& fit = *box;
        const std::array<FaceResult, 5> faces = FaceEnvelopes(cloud, fit, views, config);
        EnclosingCuboid c;
        for (std::size_t f = 0; f < 5; ++f) c.excess_m[f] = faces[f].excess_m;
        const Eigen::Vector2d a = fit.length_axis, b(-a.y(), a.x());
        const double lu = fit.length_m + faces[0].excess_m + faces[1].excess_m;
        const double lv = fit.width_m + faces[2].excess_m + faces[3].excess_m;
        c.center_m = fit.center_m + 0.5 * (faces[0].excess_m - faces[1].excess_m) * a +
                     0.5 * (faces[2].excess_m - faces[3].excess_m) * b;
        c.length_m = std::max(lu, lv);
        c.width_m = std::min(lu, lv);
        c.length_axis = lu >= lv ? a : b;
        c.height_m = fit.height_m + faces[4].excess_m;
        // Each side's excess against the box size across it: the sides against the footprint's
        // other dimension... the face's own span is what a bulge is measured against.
        const std::array<double, 5> span = {fit.width_m, fit.width_m, fit.length_m, fit.length_m,
                                            std::min(fit.length_m, fit.width_m)};
        for (std::size_t f = 0; f < 5; ++f) {
            c.max_relative_excess = std::max(c.max_relative_excess, faces[f].excess_m / span[f]);
        }
        // A face's position: the spread of its offset over the views, and when it stands out,
        // the cell that says how far.
        auto face_sigma = [&faces](std::size_t f) {
            return std::hypot(faces[f].offset_se_m, faces[f].excess_se_m);
        };
        const double s_u = std::hypot(face_sigma(0), face_sigma(1));
        const double s_v = std::hypot(face_sigma(2), face_sigma(3));
        c.sigma_m = {lu >= lv ? s_u : s_v, lu >= lv ? s_v : s_u, face_sigma(4)};
        c.fill = FillRatio(cloud, c, config);
        c.cuboid = c.fill >= config.min_fill && c.max_relative_excess <= config.max_relative_excess;
        if (c.cuboid) return c;
    }
    // No flat faces at right angles: the support function of the surface.
    const double sigma = box ? std::max(box->face_sigma_m, 0.001) : 0.003;
    auto c = EnvelopeCuboid(cloud, sigma, config);
    if (!c) return c;
    c->cuboid = false;
    c->fill = FillRatio(cloud, *c, config);
    return c;
}

}  // namespace boxd
