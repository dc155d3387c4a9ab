#include "pipeline/frames/depth_levels.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "pipeline/core/median.h"

namespace boxd {

namespace {

constexpr std::size_t kValues = 65536;
constexpr std::size_t kEnoughReadings = 300000;
// Where levels lie at least this many units apart, each has a recorded value of its own and the
// values between them stay empty: the test of the readings against the levels has its power
// there. Below one unit apart, several levels round to one value, which keeps its own depth.
constexpr double kSparseUnits = 1.5;
// A value is read at the level nearest it when that level lies within half a unit of it, give or
// take kSlackUnits for the fit's own error (microns at the ends of its range; without the slack
// a level a hair from half a unit would keep its value's depth, half a unit off). Two levels
// can then not both claim a value where they lie more than 1 + 2 kSlackUnits apart; one slack
// more is the margin.
constexpr double kSlackUnits = 0.05;
constexpr double kUniqueUnits = 1.0 + 3.0 * kSlackUnits;
// The spacing's first estimate reads pairs at least this many units apart: every such pair's
// values differ by two or more, so the pairs that rounding brought closer are counted too.
constexpr double kStartUnits = 2.5;
// Enough pairs and fitted values to place the levels, and the share of the readings where they
// are sparse that must round from a level for the levels to be the readings' (a reading off
// them is a sensor that does not work in such levels, not noise: every reading is a level).
constexpr std::size_t kMinPairs = 20;
constexpr int kMinFitted = 20;
constexpr double kMinOnLevel = 0.99;
// A value read at least this share of the median value's count (and twice) places levels.
constexpr double kOftenShare = 0.05;
// The first window of the fit, in levels either side of its middle; it doubles until it holds
// every sparse value (each doubling keeps the index error the slope's error causes at its edge
// well under half a level).
constexpr double kFirstWindowLevels = 4.0;

struct Recorded {
    int value;            // the recorded value
    double u;             // its 1/z (1/m)
    std::uint64_t count;  // how many readings it has
};

// The levels' spacing in units at `u`: dz = du / u^2.
double SpacingUnits(double spacing_per_m, double u, double unit) {
    return spacing_per_m / (u * u * unit);
}

// A recorded value given a level: the level's index and the range of 1/z that rounds to it.
struct Assigned {
    double k, lo, hi;
};

// Returns the values of `sparse` whose u lies within `half_window` of `middle`, each given the
// level index the fit (a, spacing) puts nearest, without those farther from their level than
// its rounding allows.
std::vector<Assigned> Assign(const std::vector<Recorded>& sparse, double middle, double half_window,
                             double unit, double a, double spacing) {
    std::vector<Assigned> out;
    for (const Recorded& r : sparse) {
        if (std::abs(r.u - middle) > half_window) continue;
        const double k = std::round((r.u - a) / spacing);
        // Half a unit of rounding in depth, with a little room: du = dz * u^2.
        if (std::abs(r.u - (a + k * spacing)) > 0.6 * unit * r.u * r.u) continue;
        out.push_back({k, 1.0 / ((r.value + 0.5) * unit), 1.0 / ((r.value - 0.5) * unit)});
    }
    return out;
}

// The least-squares line u = a + k * spacing through the middles of `values`' ranges; false
// when they do not determine one.
bool FitLine(const std::vector<Assigned>& values, double* a, double* spacing) {
    double sk = 0, su = 0, skk = 0, sku = 0;
    const auto n = static_cast<double>(values.size());
    for (const Assigned& v : values) {
        const double u = 0.5 * (v.lo + v.hi);
        sk += v.k;
        su += u;
        skk += v.k * v.k;
        sku += v.k * u;
    }
    const double det = n * skk - sk * sk;
    if (values.size() < 3 || !(det > 0.0)) return false;
    *spacing = (n * sku - sk * su) / det;
    *a = (su - *spacing * sk) / n;
    return true;
}

// The width of the range of a that puts every value's level inside its rounding range at
// `spacing` (negative when none does), and that range's middle.
std::pair<double, double> FeasibleLevels(const std::vector<Assigned>& values, double spacing) {
    double low = -1e300, high = 1e300;
    for (const Assigned& v : values) {
        low = std::max(low, v.lo - v.k * spacing);
        high = std::min(high, v.hi - v.k * spacing);
    }
    return {high - low, 0.5 * (low + high)};
}

// Refines the line of FitLine: the least squares place the levels only to about a third of a
// unit (the rounding's spread, 1/√12) over the square root of their number, microns too many
// for a level a hair from half a unit off its value; but every value says within which range its
// level lies, and the lines that meet all of them form a narrow convex set. Its width in a is
// concave in the spacing: a ternary search finds a spacing inside the set, bisections its two
// ends, and the line is the middle of the set at the middle spacing. Unchanged when no line
// meets them all.
void Tighten(const std::vector<Assigned>& values, double* a, double* spacing) {
    constexpr int kSteps = 100;
    const double left = *spacing * (1.0 - 1e-3), right = *spacing * (1.0 + 1e-3);
    double lo = left, hi = right;
    for (int i = 0; i < kSteps; ++i) {
        const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
        if (FeasibleLevels(values, m1).first < FeasibleLevels(values, m2).first) {
            lo = m1;
        } else {
            hi = m2;
        }
    }
    const double inside = 0.5 * (lo + hi);
    if (!(FeasibleLevels(values, inside).first >= 0.0)) return;
    // The set's ends: where the width, rising towards `inside` and falling after it, is 0.
    auto end = [&](double out, double in) {
        for (int i = 0; i < kSteps; ++i) {
            const double mid = 0.5 * (out + in);
            (FeasibleLevels(values, mid).first >= 0.0 ? in : out) = mid;
        }
        return in;
    };
    *spacing = 0.5 * (end(left, inside) + end(right, inside));
    *a = FeasibleLevels(values, *spacing).second;
}

// The level nearest `u`, as its depth in metres.
double NearestLevelDepth(const DepthLevels& levels, double u) {
    const double k = std::round((u - levels.first_per_m) / levels.spacing_per_m);
    return 1.0 / (levels.first_per_m + k * levels.spacing_per_m);
}

// The values the frames recorded, by increasing depth, with how often each was read. A few
// hundred thousand readings show every level many times over: with more frames, a stride through
// each. Four bytes a count keep the histogram in the cache.
std::vector<Recorded> RecordedValues(const std::vector<DepthImage>& frames, double depth_unit_m) {
    std::size_t readings = 0;
    for (const DepthImage& f : frames) readings += f.pixels.size();
    const std::size_t stride = std::max<std::size_t>(1, readings / kEnoughReadings);
    std::vector<std::uint32_t> counts(kValues, 0);
    for (const DepthImage& f : frames) {
        for (std::size_t i = 0; i < f.pixels.size(); i += stride) ++counts[f.pixels[i]];
    }
    std::vector<Recorded> all;
    for (std::size_t v = 1; v < kValues; ++v) {
        if (counts[v] > 0) {
            all.push_back(
                {static_cast<int>(v), 1.0 / (static_cast<double>(v) * depth_unit_m), counts[v]});
        }
    }
    return all;
}

// The values read often: the levels are placed by them (a stray value between two levels would
// split their pair); every reading is tested against them.
std::vector<Recorded> ReadOften(const std::vector<Recorded>& all) {
    std::vector<double> seen;
    for (const Recorded& r : all) seen.push_back(static_cast<double>(r.count));
    const double often = std::max(2.0, Median(std::move(seen)) * kOftenShare);
    std::vector<Recorded> values;
    for (const Recorded& r : all) {
        if (static_cast<double>(r.count) >= often) values.push_back(r);
    }
    return values;
}

// The levels' spacing in 1/m: the median gap where consecutive values are two units apart or
// more, then again where the levels that spacing gives lie kStartUnits apart or more; 0 when
// too few pairs show it.
double LevelSpacing(const std::vector<Recorded>& values, double depth_unit_m) {
    auto pair_gaps = [&](double min_units, double spacing) {
        std::vector<double> gaps;
        for (std::size_t i = 0; i + 1 < values.size(); ++i) {
            const double du = values[i].u - values[i + 1].u;
            const bool apart = spacing > 0.0
                                   ? SpacingUnits(spacing, values[i].u, depth_unit_m) >= min_units
                                   : values[i + 1].value - values[i].value >= 2;
            if (apart) gaps.push_back(du);
        }
        return gaps.size() >= kMinPairs ? Median(gaps) : 0.0;
    };
    const double spacing = pair_gaps(0.0, 0.0);
    return spacing > 0.0 ? pair_gaps(kStartUnits, spacing) : 0.0;
}

// The share of the readings where the levels are sparse that round from one of them.
double OnLevelShare(const std::vector<Recorded>& all, const DepthLevels& levels,
                    double depth_unit_m) {
    std::uint64_t on = 0, total = 0;
    for (const Recorded& r : all) {
        if (SpacingUnits(levels.spacing_per_m, r.u, depth_unit_m) < kSparseUnits) continue;
        total += r.count;
        const double z = NearestLevelDepth(levels, r.u);
        if (std::abs(z / depth_unit_m - r.value) <= 0.5 + kSlackUnits) on += r.count;
    }
    return total > 0 ? static_cast<double>(on) / static_cast<double>(total) : 0.0;
}

}  // namespace

std::optional<DepthLevels> FindDepthLevels(const std::vector<DepthImage>& frames,
                                           double depth_unit_m) {
    if (!(depth_unit_m > 0.0)) return std::nullopt;
    const std::vector<Recorded> all = RecordedValues(frames, depth_unit_m);
    if (all.empty()) return std::nullopt;
    const std::vector<Recorded> values = ReadOften(all);
    double spacing = LevelSpacing(values, depth_unit_m);
    if (!(spacing > 0.0)) return std::nullopt;
    std::vector<Recorded> sparse;
    for (const Recorded& r : values) {
        if (SpacingUnits(spacing, r.u, depth_unit_m) >= kSparseUnits) sparse.push_back(r);
    }
    if (sparse.size() < static_cast<std::size_t>(kMinFitted)) return std::nullopt;
    // Windows that double about the sparse values' middle, until one holds them all.
    const double middle = sparse[sparse.size() / 2].u;
    const double reach = std::max(sparse.front().u - middle, middle - sparse.back().u);
    double a = middle;
    DepthLevels levels;
    for (double half = kFirstWindowLevels * spacing;; half *= 2.0) {
        const std::vector<Assigned> fitted = Assign(sparse, middle, half, depth_unit_m, a, spacing);
        if (!FitLine(fitted, &a, &spacing) || !(spacing > 0.0)) return std::nullopt;
        levels.fitted = static_cast<int>(fitted.size());
        if (half > reach) {
            Tighten(fitted, &a, &spacing);
            break;
        }
    }
    levels.first_per_m = a;
    levels.spacing_per_m = spacing;
    if (levels.fitted < kMinFitted) return std::nullopt;
    // Nearly every reading where the levels are sparse must round from one of them.
    levels.on_level = OnLevelShare(all, levels, depth_unit_m);
    if (levels.on_level < kMinOnLevel) return std::nullopt;
    levels.lowest = all.front().value;
    levels.highest = all.back().value;
    return levels;
}

double RecordedDepth(const DepthLevels& levels, int value, double depth_unit_m) {
    const double z = static_cast<double>(value) * depth_unit_m;
    if (value <= 0) return z;
    const double u = 1.0 / z;
    if (SpacingUnits(levels.spacing_per_m, u, depth_unit_m) < kUniqueUnits) return z;
    const double level = NearestLevelDepth(levels, u);
    return std::abs(level / depth_unit_m - static_cast<double>(value)) <= 0.5 + kSlackUnits ? level
                                                                                            : z;
}

}  // namespace boxd
