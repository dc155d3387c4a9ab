#include "pipeline/enclosing_cuboid.h"

#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <unordered_map>
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

// A cell of an outer layer: the readings' offsets along the direction judged (as CellStats) and
// their 3-D scatter in (across, up, along) coordinates, which gives the surface's orientation.
struct LayerCell : CellStats {
    Eigen::Vector3d sum3 = Eigen::Vector3d::Zero();
    Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();
    void Add3(double a, double b, double s) {
        Add(s);
        const Eigen::Vector3d p(a, b, s);
        sum3 += p;
        sum_outer += p * p.transpose();
    }
    // Returns |cos| of the angle between the surface's normal and the direction judged.
    double Facing() const {
        const Eigen::Vector3d mean = sum3 / n;
        const Eigen::Matrix3d cov = sum_outer / n - mean * mean.transpose();
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
        return std::abs(eig.eigenvectors().col(0).z());
    }
};

// Returns Φ⁻¹(0.5^(1/m)): the median of the largest of m standard normal draws.
double MedianOfLargest(int m) { return UpperNormalQuantile(1.0 - std::pow(0.5, 1.0 / m)); }

// How far the surface reaches along the cells' axis: the cells whose means could be the largest
// (within two standard errors of it) compete, and the largest of their means is corrected by the
// median of the largest of that many noise draws — noise alone then moves the estimate neither
// out nor in. A flat face has many such cells (a large correction), a tube's tangent few.
// `se` is the chosen cell's standard error, `judged` the number of cells with enough points.
// Returns -inf when no cell is judged.
double LargestBound(const std::vector<LayerCell>& cells, const EnvelopeConfig& config,
                    double noise_sigma, double* se, int* judged) {
    // A cell's outer layer is either a surface facing the direction (its readings spread by the
    // noise alone: the mean is the surface) or a surface running along it, a wall whose end is
    // the extreme: its readings spread evenly over the layer, and the end lies √3 extent standard
    // deviations (the spread beyond the noise) above their mean. The layer's own 3-D scatter says
    // which: its normal points along the direction for a facing surface (within 60 degrees).
    // The spread must also exceed the noise by more than a sample variance wanders (three of
    // its standard errors, σ² √(2 / (n − 1))), or noise in a facing cell would pass for a wall.
    auto reach = [noise_sigma](const LayerCell& c) {
        const double var = std::max(0.0, (c.sum_sq - c.sum * c.sum / c.n) / std::max(1, c.n - 1));
        const double noise_var = noise_sigma * noise_sigma;
        const double excess_var = var - noise_var;
        if (c.Facing() >= 0.5 || excess_var <= 3.0 * noise_var * std::sqrt(2.0 / (c.n - 1))) {
            return c.Mean();
        }
        return c.Mean() + std::sqrt(3.0 * excess_var);
    };
    int m = 0;
    double top = -INFINITY, top_se = 0.0;
    for (const LayerCell& c : cells) {
        if (c.n < config.min_cell_points) continue;
        ++m;
        if (reach(c) > top) {
            top = reach(c);
            top_se = c.StdError();
        }
    }
    *judged = m;
    if (m == 0) return -INFINITY;
    auto competes = [&](const LayerCell& c) {
        return c.n >= config.min_cell_points && reach(c) >= top - 2.0 * (c.StdError() + top_se);
    };
    int contenders = 0;
    for (const LayerCell& c : cells) contenders += competes(c) ? 1 : 0;
    const double z = MedianOfLargest(contenders);
    double best = -INFINITY;
    for (const LayerCell& c : cells) {
        if (!competes(c)) continue;
        const double bound = reach(c) - z * c.StdError();
        if (bound > best) {
            best = bound;
            *se = c.StdError();
        }
    }
    return best;
}

// A dense grid of cells over a rectangle of the (a, b) plane.
template <typename Cell>
struct CellGrid {
    double a0, b0, da, db;
    int na, nb;
    std::vector<Cell> cells;
    CellGrid(double a_lo, double a_hi, double b_lo, double b_hi, double cell_a, double cell_b)
        : a0(a_lo), b0(b_lo), da(cell_a), db(cell_b) {
        na = std::max(1, static_cast<int>(std::ceil((a_hi - a_lo) / cell_a)));
        nb = std::max(1, static_cast<int>(std::ceil((b_hi - b_lo) / cell_b)));
        cells.resize(static_cast<std::size_t>(na) * static_cast<std::size_t>(nb));
    }
    Cell* At(double a, double b) {
        const int i = static_cast<int>(std::floor((a - a0) / da));
        const int j = static_cast<int>(std::floor((b - b0) / db));
        if (i < 0 || j < 0 || i >= na || j >= nb) return nullptr;
        return &cells[static_cast<std::size_t>(j) * static_cast<std::size_t>(na) +
                      static_cast<std::size_t>(i)];
    }
};

struct FaceResult {
    double excess_m = 0.0;
    double excess_se_m = 0.0;    // standard error of the cell that set the excess
    double offset_se_m = 0.0;    // standard error of the face plane's offset, from the views
    double view_spread_m = 0.0;  // standard deviation of the plane's offset between the views
};

// One face's cells, each with its points' offsets from the face plane kept per view: the views
// are the independent samples (a view's neighbouring readings share its registration error and
// its sensor's disparity steps, so its points are not).
struct FaceCells {
    int views = 1;
    std::unordered_map<std::size_t, CellStats> cell_view;  // key cell * views + view
    std::vector<CellStats> view_plane;                     // per view: offsets near the plane

    FaceResult Evaluate(const EnvelopeConfig& config, double point_sigma,
                        double agreement_m) const {
        // Each cell's mean over its views' means, and the views' spread pooled over the face.
        std::unordered_map<std::size_t, CellStats> cells;
        for (const auto& [key, st] : cell_view) {
            if (st.n >= 3) cells[key / static_cast<std::size_t>(views)].Add(st.Mean());
        }
        double pooled = 0.0;
        int dof = 0, total = 0;
        for (const auto& [cell, st] : cells) {
            if (st.n >= 2) {
                pooled += st.sum_sq - st.sum * st.sum / st.n;
                dof += st.n - 1;
            }
        }
        for (const auto& [key, st] : cell_view) total += st.n;
        // Without a second view of any cell (one pose), the within-view noise of a cell's mean,
        // its readings counted as a tenth as many independent ones.
        const double spread = dof >= 10 ? std::sqrt(pooled / dof) : point_sigma;
        std::vector<CellStats> judged;
        std::vector<double> se;
        for (const auto& [cell, st] : cells) {
            if (st.n * 3 < config.min_cell_points && dof >= 10) continue;
            judged.push_back(st);
            se.push_back(dof >= 10
                             ? spread / std::sqrt(st.n)
                             : spread / std::sqrt(std::max(1.0, total / 10.0 / cells.size())));
        }
        // The plane's offset as each view sees it: their spread is the registration's and the
        // noise's contribution to the face's position.
        CellStats offsets;
        for (const CellStats& v : view_plane) {
            if (v.n >= 4 * config.min_cell_points) offsets.Add(v.Mean());
        }
        FaceResult out;
        out.view_spread_m = offsets.n >= 2 ? offsets.StdError() * std::sqrt(offsets.n) : 0.0;
        out.offset_se_m = offsets.n >= 2
                              ? offsets.StdError()
                              : spread / std::sqrt(std::max<std::size_t>(1, cells.size()));
        // Views that disagree about where the face is (a miscalibrated station, an object that
        // flexed) make cells stand out that are no surface of the object: a cell must also stand
        // out beyond the views' spread about the plane.
        const double threshold =
            std::max(agreement_m, offsets.n >= 2 ? offsets.StdError() * std::sqrt(offsets.n) : 0.0);
        // Detection: a cell counts as standing out when its lower bound passes the plane with
        // the Bonferroni confidence over all the face's cells; the excess is then the largest
        // mean among those cells, less the median of the largest of that many noise draws.
        const int m = static_cast<int>(judged.size());
        if (m > 0) {
            const double k = UpperNormalQuantile(config.false_alarm / m);
            int significant = 0;
            auto stands_out = [&](int i) { return judged[i].Mean() - k * se[i] > threshold; };
            for (int i = 0; i < m; ++i) significant += stands_out(i) ? 1 : 0;
            if (significant > 0) {
                const double z = MedianOfLargest(significant);
                for (int i = 0; i < m; ++i) {
                    if (!stands_out(i)) continue;
                    const double excess = judged[i].Mean() - z * se[i];
                    if (excess > out.excess_m) {
                        out.excess_m = excess;
                        out.excess_se_m = se[i];
                    }
                }
            }
        }
        return out;
    }
};

// The excess of the 4 side faces and the top of `box` over their fitted planes, and the
// uncertainty of each plane from the spread of its offset between views.
std::array<FaceResult, 5> FaceEnvelopes(const FusedCloud& cloud, const BoxFit& box, int views,
                                        double agreement_m, const EnvelopeConfig& config) {
    const Eigen::Vector2d a = box.length_axis, b(-a.y(), a.x());
    const double hl = box.length_m / 2.0, hw = box.width_m / 2.0, h = box.height_m;
    const double m = config.edge_margin_m;
    const double inward = std::max(config.inward_band_sigmas * box.face_sigma_m, 0.004);
    using Grid = CellGrid<CellStats>;
    std::array<Grid, 5> grids = {
        Grid(-hw + m, hw - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hw + m, hw - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hl + m, hl - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hl + m, hl - m, m, h - m, config.cell_along_m, config.cell_height_m),
        Grid(-hl + m, hl - m, -hw + m, hw - m, config.cell_along_m, config.cell_along_m)};
    const int nv = std::max(views, 1);
    std::array<FaceCells, 5> faces;
    for (FaceCells& f : faces) {
        f.views = nv;
        f.view_plane.resize(static_cast<std::size_t>(nv));
    }
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
        const Eigen::Vector3f& p3 = cloud.points[i];
        const Eigen::Vector2d q = p3.head<2>().cast<double>() - box.center_m;
        const double u = a.dot(q), v = b.dot(q), z = p3.z();
        const std::size_t view =
            i < cloud.view.size() ? std::min<std::size_t>(cloud.view[i], nv - 1) : 0;
        // Offset outside each face, and the face's own coordinates of the point.
        const std::array<double, 5> s = {u - hl, -u - hl, v - hw, -v - hw, z - h};
        const std::array<double, 5> ca = {v, -v, -u, u, u};
        const std::array<double, 5> cb = {z, z, z, z, v};
        for (std::size_t f = 0; f < 5; ++f) {
            if (s[f] < -inward || s[f] > config.outward_band_m) continue;
            CellStats* c = grids[f].At(ca[f], cb[f]);
            if (c == nullptr) continue;
            const auto cell = static_cast<std::size_t>(c - grids[f].cells.data());
            faces[f].cell_view[cell * static_cast<std::size_t>(nv) + view].Add(s[f]);
            if (s[f] <= inward) faces[f].view_plane[view].Add(s[f]);
        }
    }
    std::array<FaceResult, 5> out;
    for (std::size_t f = 0; f < 5; ++f) {
        out[f] = faces[f].Evaluate(config, std::max(box.face_sigma_m, 0.0005), agreement_m);
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
    CellGrid<LayerCell> front(-radius, radius, 0.0, top, config.cell_along_m, config.cell_height_m);
    CellGrid<LayerCell> back = front;
    std::vector<double> max_s(front.cells.size(), -INFINITY), min_s(front.cells.size(), INFINITY);
    auto index = [&front](const LayerCell* c) {
        return static_cast<std::size_t>(c - front.cells.data());
    };
    for (const Eigen::Vector3f& p : pts) {
        const Eigen::Vector2d q = p.head<2>().cast<double>();
        if (LayerCell* c = front.At(v.dot(q), p.z())) {
            const std::size_t k = index(c);
            const double s = u.dot(q);
            max_s[k] = std::max(max_s[k], s);
            min_s[k] = std::min(min_s[k], s);
        }
    }
    const double layer = config.layer_sigmas * sigma;
    for (const Eigen::Vector3f& p : pts) {
        const Eigen::Vector2d q = p.head<2>().cast<double>();
        LayerCell* c = front.At(v.dot(q), p.z());
        if (c == nullptr) continue;
        const std::size_t k = index(c);
        const double s = u.dot(q), t = v.dot(q);
        if (s >= max_s[k] - layer) c->Add3(t, p.z(), s);
        if (s <= min_s[k] + layer) back.cells[k].Add3(-t, p.z(), -s);
    }
    Support out;
    int judged = 0;
    out.forward = LargestBound(front.cells, config, sigma, &out.se_forward, &judged);
    out.backward = LargestBound(back.cells, config, sigma, &out.se_backward, &judged);
    return out;
}

// An even subsample of the cloud above the table (at most config.max_points), and how far it
// reaches from the axis and up, with a centimetre to spare.
struct Surface {
    std::vector<Eigen::Vector3f> points;
    double radius = 0.0, top = 0.0;
};

Surface SurfaceAbove(const FusedCloud& cloud, const EnvelopeConfig& config) {
    Surface out;
    std::size_t above = 0;
    for (const Eigen::Vector3f& p : cloud.points) above += p.z() >= config.min_z_m ? 1 : 0;
    const std::size_t step =
        std::max<std::size_t>(1, above / static_cast<std::size_t>(config.max_points));
    std::size_t k = 0;
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() < config.min_z_m || (k++ % step) != 0) continue;
        out.points.push_back(p);
        out.radius = std::max(out.radius, static_cast<double>(p.head<2>().norm()));
        out.top = std::max(out.top, static_cast<double>(p.z()));
    }
    out.radius += 0.01;
    out.top += 0.01;
    return out;
}

// The height: the top's outer layer over (x, y) cells.
double TopBound(const std::vector<Eigen::Vector3f>& pts, double sigma, double radius,
                const EnvelopeConfig& config, double* se) {
    CellGrid<LayerCell> grid(-radius, radius, -radius, radius, 2.0 * config.cell_along_m,
                             2.0 * config.cell_along_m);
    std::vector<double> max_z(grid.cells.size(), -INFINITY);
    for (const Eigen::Vector3f& p : pts) {
        if (LayerCell* c = grid.At(p.x(), p.y())) {
            const auto k = static_cast<std::size_t>(c - grid.cells.data());
            max_z[k] = std::max(max_z[k], static_cast<double>(p.z()));
        }
    }
    for (const Eigen::Vector3f& p : pts) {
        if (LayerCell* c = grid.At(p.x(), p.y())) {
            const auto k = static_cast<std::size_t>(c - grid.cells.data());
            if (p.z() >= max_z[k] - config.layer_sigmas * sigma) c->Add3(p.x(), p.y(), p.z());
        }
    }
    int judged = 0;
    return LargestBound(grid.cells, config, sigma, se, &judged);
}

// The least-area footprint rectangle of the support function, and the height.
Result<EnclosingCuboid> EnvelopeCuboid(const FusedCloud& cloud, double sigma,
                                       const EnvelopeConfig& config) {
    const Surface surface = SurfaceAbove(cloud, config);
    const std::vector<Eigen::Vector3f>& pts = surface.points;
    if (pts.empty()) return Error{ErrorCode::kInsufficientData, "no surface above the table"};
    const double radius = surface.radius, top = surface.top;
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

// Returns the area of the convex hull of the centres of the cells (of `cell` metres) that hold
// at least `min_points` of `points`.
double CellHullArea(const std::vector<Eigen::Vector2d>& points, double cell, int min_points) {
    std::map<std::pair<int, int>, int> counts;
    for (const Eigen::Vector2d& p : points) {
        ++counts[{static_cast<int>(std::floor(p.x() / cell)),
                  static_cast<int>(std::floor(p.y() / cell))}];
    }
    std::vector<cv::Point2f> centres;
    for (const auto& [key, n] : counts) {
        if (n < min_points) continue;
        centres.emplace_back(static_cast<float>((key.first + 0.5) * cell),
                             static_cast<float>((key.second + 0.5) * cell));
    }
    if (centres.size() < 3) return 0.0;
    std::vector<cv::Point2f> hull;
    cv::convexHull(centres, hull);
    return cv::contourArea(hull);
}

// The area of the convex hull of the footprint over the rectangle's: 1 for a box, pi/4 for a
// tube standing, 7/8 for an L of a quarter cut away. Noise scatters single readings a few sigma
// beyond the surface, and a hull of readings would grow by that all round; the hull is therefore
// taken of the footprint cells that hold several readings (scattered readings rarely share a
// cell), and compared with the same hull of the rectangle itself, filled and cut into the same
// cells, so that the cells' own coarseness cancels.
double FillRatio(const FusedCloud& cloud, const EnclosingCuboid& c, const EnvelopeConfig& config) {
    const double cell = config.fill_cell_m;
    std::vector<Eigen::Vector2d> footprint;
    for (const Eigen::Vector3f& p : SurfaceAbove(cloud, config).points) {
        footprint.push_back(p.head<2>().cast<double>());
    }
    const Eigen::Vector2d a = c.length_axis, b(-a.y(), a.x());
    std::vector<Eigen::Vector2d> rectangle;
    const double step = cell / 4.0;
    for (double u = -c.length_m / 2.0 + step / 2.0; u < c.length_m / 2.0; u += step) {
        for (double v = -c.width_m / 2.0 + step / 2.0; v < c.width_m / 2.0; v += step) {
            rectangle.push_back(c.center_m + u * a + v * b);
        }
    }
    const double reference = CellHullArea(rectangle, cell, 1);
    if (reference <= 0.0) return 0.0;
    return std::min(1.0, CellHullArea(footprint, cell, config.fill_cell_points) / reference);
}

// One view: the cuboid assumption. The view shows the top and one or two sides; the faces it
// does not show are assumed to stand where the top's edges end, so the footprint is the least-
// area rectangle of the top's readings (every pixel: with nothing to fuse, their edges are the
// measurement) and the height the top's median. Each edge is then known to about a reading's
// spacing plus the noise, and that is its uncertainty.
Result<EnclosingCuboid> SingleViewCuboid(const FusedCloud& cloud, double noise_sigma,
                                         const EnvelopeConfig& config) {
    std::vector<float> z;
    for (const Eigen::Vector3f& p : cloud.points) {
        if (p.z() >= config.min_z_m) z.push_back(p.z());
    }
    if (z.empty()) return Error{ErrorCode::kInsufficientData, "no surface above the table"};
    const auto q = static_cast<long>(0.995 * static_cast<double>(z.size() - 1));
    std::nth_element(z.begin(), z.begin() + q, z.end());
    const double top = z[static_cast<std::size_t>(q)];
    const double band = std::max(4.0 * noise_sigma, 0.01);
    std::vector<cv::Point2f> footprint;
    std::vector<double> heights;
    for (const Eigen::Vector3f& p : cloud.points) {
        if (std::abs(p.z() - top) > band) continue;
        footprint.emplace_back(p.x(), p.y());
        heights.push_back(p.z());
    }
    // The highest readings must be a top: a horizontal surface, not the upper strip of a wall.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    for (std::size_t i = 0; i < footprint.size(); ++i) {
        const Eigen::Vector3d p(footprint[i].x, footprint[i].y, heights[i]);
        mean += p;
        outer += p * p.transpose();
    }
    bool horizontal = false;
    if (!footprint.empty()) {
        mean /= static_cast<double>(footprint.size());
        const Eigen::Matrix3d cov =
            outer / static_cast<double>(footprint.size()) - mean * mean.transpose();
        horizontal =
            std::abs(
                Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0).z()) >
            std::cos(M_PI / 6.0);
    }
    if (static_cast<int>(footprint.size()) < 10 * config.min_cell_points || !horizontal) {
        return Error{ErrorCode::kInsufficientData,
                     "a single view that shows no top face cannot bound the object"};
    }
    // Mixed readings at the top's far edge (between the top and the table behind it) lie
    // beyond the edge, sparsely: the top's footprint is its densely read cells (a cell twice the
    // readings' spacing holds about four; one holding less than half the typical count is edge
    // or stray), whose centres span the top to within half a cell at each edge.
    std::vector<cv::Point2f> raw_hull;
    cv::convexHull(footprint, raw_hull);
    const double raw_spacing = std::sqrt(cv::contourArea(raw_hull) / footprint.size());
    const double cell = std::max(2.0 * raw_spacing, 0.002);
    std::map<std::pair<int, int>, int> counts;
    for (const cv::Point2f& p : footprint) {
        ++counts[{static_cast<int>(std::floor(p.x / cell)),
                  static_cast<int>(std::floor(p.y / cell))}];
    }
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
    std::nth_element(heights.begin(), heights.begin() + static_cast<long>(heights.size() / 2),
                     heights.end());
    c.height_m = heights[heights.size() / 2];
    // An edge is known to within its cell (uniform over it: sigma cell / √12) and the readings'
    // spacing (how far the last reading may stand from the true edge).
    const double spacing = raw_spacing;
    const double edge = std::hypot(cell / std::sqrt(12.0), spacing);
    c.sigma_m = {std::sqrt(2.0) * edge, std::sqrt(2.0) * edge,
                 noise_sigma / std::sqrt(static_cast<double>(heights.size())) + 0.5 * spacing};
    c.cuboid = true;
    c.assumed = true;
    c.fill = std::min(1.0, cv::contourArea(hull) / std::max(a * b, 1e-12));
    return c;
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
    if (!(min_fill > 0.0 && min_fill <= 1.0)) return bad("min_fill", "in (0, 1]");
    if (!(fill_cell_m > 0.0 && fill_cell_m < 0.05)) return bad("fill_cell_m", "in (0, 0.05)");
    if (fill_cell_points < 1) return bad("fill_cell_points", "must be >= 1");
    if (!(max_relative_excess > 0.0)) return bad("max_relative_excess", "must be > 0");
    if (!(max_view_spread_rmse > 0.0)) return bad("max_view_spread_rmse", "must be > 0");
    return OkStatus();
}

Result<EnclosingCuboid> FitEnclosingCuboid(const FusedCloud& cloud, const Result<BoxFit>& box,
                                           int views, double agreement_m, double noise_sigma_m,
                                           const EnvelopeConfig& config) {
    if (views == 1) return SingleViewCuboid(cloud, std::max(noise_sigma_m, 0.0005), config);
    if (box) {
        const BoxFit& fit = *box;
        const std::array<FaceResult, 5> faces =
            FaceEnvelopes(cloud, fit, views, agreement_m, config);
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
        double top_se = 0.0;
        if (!fit.top_observed) {
            // No top face to fit: the height is where the side faces end.
            const Surface surface = SurfaceAbove(cloud, config);
            c.height_m = TopBound(surface.points, std::max(noise_sigma_m, 0.0005), surface.radius,
                                  config, &top_se);
        }
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
        c.sigma_m = {lu >= lv ? s_u : s_v, lu >= lv ? s_v : s_u,
                     fit.top_observed ? face_sigma(4) : top_se};
        c.fill = FillRatio(cloud, c, config);
        // A flat face stands where every view sees it, up to the views' registration; a curved
        // "face" (a tube's side) stands where each view's tangent is.
        double spread = 0.0;
        for (const FaceResult& f : faces) spread = std::max(spread, f.view_spread_m);
        c.cuboid = c.fill >= config.min_fill &&
                   c.max_relative_excess <= config.max_relative_excess &&
                   spread <= config.max_view_spread_rmse * std::max(agreement_m, noise_sigma_m / 4);
        spdlog::debug(
            "envelope: face excess {:.2f} {:.2f} {:.2f} {:.2f} top {:.2f} mm (cell se {:.2f} "
            "{:.2f} "
            "{:.2f} {:.2f} {:.2f}), plane se {:.2f} {:.2f} {:.2f} {:.2f} {:.2f} mm, fill {:.3f}",
            faces[0].excess_m * 1e3, faces[1].excess_m * 1e3, faces[2].excess_m * 1e3,
            faces[3].excess_m * 1e3, faces[4].excess_m * 1e3, faces[0].excess_se_m * 1e3,
            faces[1].excess_se_m * 1e3, faces[2].excess_se_m * 1e3, faces[3].excess_se_m * 1e3,
            faces[4].excess_se_m * 1e3, faces[0].offset_se_m * 1e3, faces[1].offset_se_m * 1e3,
            faces[2].offset_se_m * 1e3, faces[3].offset_se_m * 1e3, faces[4].offset_se_m * 1e3,
            c.fill);
        if (c.cuboid) return c;
    }
    // No flat faces at right angles: the support function of the surface.
    // The outer layer of a cell column is the sensor's noise deep: the noise of the table top
    // about its plane, seen at about the object's distance.
    const double sigma = std::max(noise_sigma_m, 0.0005);
    auto c = EnvelopeCuboid(cloud, sigma, config);
    if (!c) return c;
    c->cuboid = false;
    c->fill = FillRatio(cloud, *c, config);
    return c;
}

}  // namespace boxd
