#include "pipeline/rounded_edges.h"

#include <cmath>
#include <cstddef>

#include "pipeline/median.h"

namespace boxd {

namespace {

// A robust level of a band of readings: the median of their outward offsets and its standard
// error (the median of normal values errs by sqrt(pi / 2) times the mean's).
struct Level {
    double median = 0.0, se = INFINITY;
};

Level LevelOf(std::vector<double> out) {
    Level l;
    if (out.size() < 2) return l;
    const auto n = static_cast<double>(out.size());
    double sum = 0.0, sq = 0.0;
    for (double v : out) sum += v;
    const double mean = sum / n;
    for (double v : out) sq += (v - mean) * (v - mean);
    l.se = std::sqrt(M_PI / 2.0) * std::sqrt(sq / (n - 1.0) / n);
    l.median = Median(std::move(out));
    return l;
}

}  // namespace

double RoundedEdgeMargin(const std::vector<EdgeSample>& samples, double margin_m, double cap_m) {
    constexpr double kStandardErrors = 3.0;
    constexpr std::size_t kBeyondSteps = 2;
    const double step = margin_m / 3.0;
    if (!(step > 0.0) || !(cap_m >= margin_m + step)) return margin_m;
    // The readings by step inwards from the margin, as far as the last step the walk compares.
    const auto steps = static_cast<std::size_t>((cap_m - margin_m) / step) + kBeyondSteps;
    std::vector<std::vector<double>> by_step(steps);
    for (const EdgeSample& s : samples) {
        const double k = std::floor((s.inside_m - margin_m) / step);
        if (k >= 0.0 && k < static_cast<double>(steps)) {
            by_step[static_cast<std::size_t>(k)].push_back(s.out_m);
        }
    }
    for (std::size_t k = 0; margin_m + static_cast<double>(k + 1) * step <= cap_m; ++k) {
        std::vector<double> next;
        for (std::size_t j = k + 1; j <= k + kBeyondSteps && j < steps; ++j) {
            next.insert(next.end(), by_step[j].begin(), by_step[j].end());
        }
        const Level near = LevelOf(by_step[k]), beyond = LevelOf(std::move(next));
        if (!std::isfinite(near.se) || !std::isfinite(beyond.se)) return margin_m;
        const double inset = beyond.median - near.median;
        if (!(inset > kStandardErrors * std::hypot(near.se, beyond.se))) {
            return margin_m + static_cast<double>(k) * step;
        }
    }
    // Falling inwards all the way: a face curved over its whole width (a bulge), no edge's
    // rounding. Its outermost surface is the envelopes' to find (face_envelope.h).
    return margin_m;
}

}  // namespace boxd
