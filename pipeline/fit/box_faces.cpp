#include "pipeline/fit/box_faces.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "pipeline/core/median.h"
#include "pipeline/core/parallel_for.h"

namespace boxd::box_faces {

namespace {

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

// The sides' normals, the footprint's half extents (u, v) and its centre in the box's frame.
struct FaceFrame {
    std::array<Eigen::Vector2d, 4> n;
    double half_u, half_v, cu, cv;
    explicit FaceFrame(const BoxState& s)
        : half_u(0.5 * (s.d[0] + s.d[1])),
          half_v(0.5 * (s.d[2] + s.d[3])),
          cu(0.5 * (s.d[0] - s.d[1])),
          cv(0.5 * (s.d[2] - s.d[3])) {
        for (int f = 0; f < 4; ++f) n[static_cast<std::size_t>(f)] = FaceNormal(s.yaw, f);
    }
};

struct FacePoint {
    int face;
    Eigen::Vector2d xy;
};

}  // namespace

Eigen::Vector2d FaceNormal(double yaw, int face) {
    const double a = yaw + (face == 0 ? 0.0 : face == 1 ? M_PI : face == 2 ? M_PI / 2 : -M_PI / 2);
    return {std::cos(a), std::sin(a)};
}

namespace {

// The readings each side's fit takes: within the side's band of its plane, clear of its edges by
// the margin (judged along each reading's ray where the rays are known, face_choice.h).
std::vector<FacePoint> SideReadings(const Points& points, const BoxFitConfig& config,
                                    const ReadingRays* rays, double margin,
                                    const std::array<double, 4>& band, const BoxState& s) {
    const FaceFrame frame(s);
    const auto& n = frame.n;
    const FaceChoice choice(rays, margin);
    const double m = choice.margin(), gate = choice.gate();
    return ParallelCollect<FacePoint>(
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
                    const double mid = f < 2 ? frame.cv : frame.cu;
                    const double half = f < 2 ? frame.half_v : frame.half_u;
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
}

// One Gauss-Newton step of the sides over the readings `use` marks (their count per side into
// `cnt`). Unknowns: dyaw, dd0..dd3; a reading's residual r + (n'·p) dyaw - dd_f = 0.
Eigen::Matrix<double, 5, 1> SolveSides(const std::vector<FacePoint>& sel,
                                       const std::vector<char>& use, const FaceFrame& frame,
                                       const BoxState& s, std::array<int, 5>& cnt) {
    const auto& n = frame.n;
    Eigen::Matrix<double, 5, 5> h = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> g = Eigen::Matrix<double, 5, 1>::Zero();
    cnt.fill(0);
    for (std::size_t i = 0; i < sel.size(); ++i) {
        if (!use[i]) continue;
        const auto k = static_cast<std::size_t>(sel[i].face);
        const Eigen::Vector2d nd(-n[k].y(), n[k].x());
        const double r = n[k].dot(sel[i].xy) - s.d[k];
        // The Jacobian row has two entries, j0 and -1 at 1 + k: only the terms they touch (h is
        // symmetric; its lower triangle is all ldlt reads).
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
}

}  // namespace

bool FitSides(const Points& points, const BoxFitConfig& config, const ReadingRays* rays,
              double margin, const std::array<double, 4>& band, BoxState& s,
              std::array<int, 5>& counts) {
    const FaceFrame frame(s);
    const auto& n = frame.n;
    const std::vector<FacePoint> sel = SideReadings(points, config, rays, margin, band, s);
    std::vector<char> use(sel.size(), 1);
    std::array<int, 5> cnt{};
    Eigen::Matrix<double, 5, 1> delta = SolveSides(sel, use, frame, s, cnt);
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
    delta = SolveSides(sel, use, frame, s, cnt);
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

bool FitTop(const Points& points, const BoxFitConfig& config, const ReadingRays* rays,
            double margin, double band, BoxState& s, std::array<int, 5>& counts) {
    const FaceFrame frame(s);
    const Eigen::Vector2d &nu = frame.n[0], &nv = frame.n[2];
    const double half_u = frame.half_u, half_v = frame.half_v, cu = frame.cu, cv = frame.cv;
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

std::vector<EdgeSample> EdgeSamples(const Points& points, const BoxFitConfig& config,
                                    const ReadingRays* rays, double margin,
                                    const std::array<double, 4>& band, double top_band,
                                    bool top_observed, const BoxState& s) {
    const FaceFrame frame(s);
    const auto& n = frame.n;
    const double half_u = frame.half_u, half_v = frame.half_v, cu = frame.cu, cv = frame.cv;
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

}  // namespace boxd::box_faces
