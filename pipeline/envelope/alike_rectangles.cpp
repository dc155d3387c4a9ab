#include "pipeline/envelope/alike_rectangles.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

namespace boxd::envelope {

namespace {

// How many standard errors the areas' bend must stand clear of zero to be read as one.
constexpr double kBendSigmas = 3.0;

// A rectangle alike: its turn from the least one (in steps), its area and its sides along u, v.
struct Turned {
    double turn = 0.0, area = 0.0, u = 0.0, v = 0.0;
};

// Parabolas c0 + c1 t + c2 t² through (t, area), (t, u) and (t, v) by least squares: the area's
// coefficients and the standard error of its c2, and the sides' coefficients.
struct Parabolas {
    Eigen::Vector3d area, u, v;
    double bend_se = INFINITY;
};

Parabolas FitParabolas(const std::vector<Turned>& alike) {
    const int n = static_cast<int>(alike.size());
    Eigen::MatrixXd a(n, 3);
    Eigen::MatrixXd y(n, 3);
    for (int k = 0; k < n; ++k) {
        const Turned& r = alike[static_cast<std::size_t>(k)];
        a.row(k) << 1.0, r.turn, r.turn * r.turn;
        y.row(k) << r.area, r.u, r.v;
    }
    const Eigen::Matrix3d normal = a.transpose() * a;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(normal);
    Parabolas out;
    if (ldlt.info() != Eigen::Success) return out;
    const Eigen::MatrixXd coef = ldlt.solve(a.transpose() * y);
    out.area = coef.col(0);
    out.u = coef.col(1);
    out.v = coef.col(2);
    if (n > 3) {
        const double rss = (y.col(0) - a * out.area).squaredNorm();
        const Eigen::Matrix3d cov = ldlt.solve(Eigen::Matrix3d::Identity()) * (rss / (n - 3));
        out.bend_se = std::sqrt(std::max(cov(2, 2), 0.0));
    }
    return out;
}

}  // namespace

Alike AlikeRectangles(const std::vector<double>& width, const std::vector<double>& width_se,
                      int best) {
    const int n = static_cast<int>(width.size());
    auto sides = [&](int i) {
        const auto a = static_cast<std::size_t>(i % n),
                   b = static_cast<std::size_t>((i + n / 2) % n);
        return std::array<double, 4>{width[a], width[b], width_se[a], width_se[b]};
    };
    auto area = [](const std::array<double, 4>& s) { return s[0] * s[1]; };
    auto area_se = [](const std::array<double, 4>& s) {
        return std::hypot(s[1] * s[2], s[0] * s[3]);
    };
    const auto least = sides(best);
    const double step = M_PI / n;
    const double faceted = 2.0 * area_se(least) / (least[0] * least[0] + least[1] * least[1]);
    std::vector<Turned> alike;
    double sum_se_u = 0.0, sum_se_v = 0.0, widest = 0.0;
    for (int i = 0; i < n / 2; ++i) {
        const auto s = sides(i);
        if (area(s) - area(least) > 2.0 * std::hypot(area_se(s), area_se(least))) continue;
        // The turn from the least rectangle, within a quarter turn either way; i's first side
        // lies along u where i is that turn from it, not a half turn more.
        int turn = ((i - best) % (n / 2) + n / 2) % (n / 2);
        if (turn >= n / 4) turn -= n / 2;
        const bool same = ((i - best - turn) / (n / 2)) % 2 == 0;
        widest = std::max(widest, step * std::abs(turn));
        alike.push_back(
            {static_cast<double>(turn), area(s), same ? s[0] : s[1], same ? s[1] : s[0]});
        sum_se_u += same ? s[2] : s[3];
        sum_se_v += same ? s[3] : s[2];
    }
    if (widest <= faceted + step) return {};
    // The areas' growth per step away from the least, by least squares over the turn.
    constexpr int kTurnSteps = 10;
    double st = 0.0, sa = 0.0, stt = 0.0, sta = 0.0;
    int points = 0;
    for (int k = 1; k <= std::min(kTurnSteps, n / 4); ++k) {
        for (int side : {-1, 1}) {
            const double a = area(sides(((best + side * k) % n + n) % n)) - area(least);
            st += k;
            sa += a;
            stt += k * k;
            sta += k * a;
            ++points;
        }
    }
    const double growth = (sta - st * sa / points) / (stt - st * st / points);
    if (growth >= 0.5 * (least[0] * least[0] + least[1] * least[1]) * step) return {};
    const auto count = static_cast<double>(alike.size());
    Alike out{static_cast<int>(alike.size()), 0.0, 0.0, sum_se_u / count, sum_se_v / count, 0.0};
    const Parabolas fit = FitParabolas(alike);
    if (fit.area(2) > kBendSigmas * fit.bend_se) {
        const auto [lo, hi] =
            std::minmax_element(alike.begin(), alike.end(),
                                [](const Turned& a, const Turned& b) { return a.turn < b.turn; });
        const double t = std::clamp(-fit.area(1) / (2.0 * fit.area(2)), lo->turn, hi->turn);
        out.along_u = fit.u(0) + t * (fit.u(1) + t * fit.u(2));
        out.along_v = fit.v(0) + t * (fit.v(1) + t * fit.v(2));
        out.turn = t * step;
        return out;
    }
    for (const Turned& r : alike) {
        out.along_u += r.u / count;
        out.along_v += r.v / count;
    }
    return out;
}

}  // namespace boxd::envelope
