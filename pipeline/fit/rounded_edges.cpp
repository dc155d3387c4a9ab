#include "pipeline/fit/rounded_edges.h"

#include <cmath>
#include <cstddef>

#include "pipeline/core/median.h"

namespace boxd {

namespace {

// A robust level of a band of readings: the median of their outward offsets and its standard
// error (the median of normal values errs by sqrt(pi / 2) times the mean's), their spread read
// from the median absolute deviation, so that the few readings of another surface a band holds
// (an adjacent face's, millimetres inside this one's plane) widen it no more than they move it.
struct Level {
    double median = 0.0, se = INFINITY;
};

Level LevelOf(std::vector<double> out) {
    Level l;
    if (out.size() < 2) return l;
    const auto n = static_cast<double>(out.size());
    l.median = Median(out);
    for (double& v : out) v = std::abs(v - l.median);
    const double sigma = 1.4826 * Median(std::move(out));
    l.se = std::sqrt(M_PI / 2.0) * sigma / std::sqrt(n);
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
    // The outward offsets of the readings from `lo` to `hi` inside the edges.
    auto from = [&](double lo, double hi) {
        std::vector<double> out;
        for (const EdgeSample& s : samples) {
            if (s.inside_m >= lo && s.inside_m < hi) out.push_back(s.out_m);
        }
        return out;
    };
    auto stands_below = [](const Level& near, const Level& beyond) {
        return beyond.median - near.median > kStandardErrors * std::hypot(near.se, beyond.se);
    };
    double m = margin_m, last_drop = 0.0;
    for (std::size_t k = 0; margin_m + static_cast<double>(k + 1) * step <= cap_m; ++k) {
        std::vector<double> next;
        for (std::size_t j = k + 1; j <= k + kBeyondSteps && j < steps; ++j) {
            next.insert(next.end(), by_step[j].begin(), by_step[j].end());
        }
        const Level near = LevelOf(by_step[k]), beyond = LevelOf(std::move(next));
        if (!std::isfinite(near.se) || !std::isfinite(beyond.se) || !stands_below(near, beyond)) {
            break;
        }
        m = margin_m + static_cast<double>(k + 1) * step;
        last_drop = beyond.median - near.median;
        if (m + step > cap_m) {
            // Falling inwards all the way: a face curved over its whole width (a bulge), no
            // edge's rounding. Its outermost surface is the envelopes' to find (face_envelope.h).
            return margin_m;
        }
    }
    if (m == margin_m) return m;
    // Where the walk stopped a rounding leaves a flat face, and a bulge goes on rising, by
    // more than it fell over the walk's last step: a rounding's fall is steep where it ends,
    // and a flat face's readings may differ from place to place by hundredths of a millimetre
    // that tens of thousands of readings make significant.
    const Level near = LevelOf(from(m, m + kBeyondSteps * step));
    const Level inner = LevelOf(from(m + kBeyondSteps * step, INFINITY));
    if (std::isfinite(near.se) && std::isfinite(inner.se) && stands_below(near, inner) &&
        inner.median - near.median > last_drop) {
        return margin_m;
    }
    return m;
}

}  // namespace boxd
