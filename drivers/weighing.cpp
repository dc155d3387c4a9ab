#include "drivers/weighing.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <thread>

namespace boxd {

namespace {

struct Sample {
    double t_ms = 0.0;
    double weight = 0.0;
    bool flag = false;
};

using Window = std::deque<Sample>;

Error ScaleFault(const Scale& scale, const std::string& what) {
    return Error{ErrorCode::kScaleError, scale.Describe() + ": " + what};
}

std::string Amount(double value, const std::string& unit) {
    return fmt::format("{:.4g} {}", value, unit);
}

double Spread(const Window& w) {
    const auto [lo, hi] = std::minmax_element(
        w.begin(), w.end(), [](const Sample& a, const Sample& b) { return a.weight < b.weight; });
    return hi->weight - lo->weight;
}

// The least-squares line through the window's readings: its slope (per ms) and how far the
// readings stray from it (the range of the residuals).
std::pair<double, double> Trend(const Window& w) {
    double st = 0, sw = 0;
    for (const Sample& s : w) {
        st += s.t_ms;
        sw += s.weight;
    }
    const double n = static_cast<double>(w.size());
    const double mt = st / n, mw = sw / n;
    double stt = 0, stw = 0;
    for (const Sample& s : w) {
        stt += (s.t_ms - mt) * (s.t_ms - mt);
        stw += (s.t_ms - mt) * (s.weight - mw);
    }
    const double slope = stt > 0 ? stw / stt : 0.0;
    double lo = 0, hi = 0;
    for (const Sample& s : w) {
        const double r = s.weight - (mw + slope * (s.t_ms - mt));
        lo = std::min(lo, r);
        hi = std::max(hi, r);
    }
    return {slope, hi - lo};
}

// Why the readings of `w` (the last stable time's) never made a stable weight.
std::string Unsettled(const Window& w, const ScaleConfig& c, double band) {
    const double span_ms = w.back().t_ms - w.front().t_ms;
    const double spread = Spread(w);
    const auto [slope, straying] = Trend(w);
    const std::string over = fmt::format("over the last {:.0f} ms", span_ms);
    // Readings shown in whole divisions stray from a straight line by up to one division more.
    if (w.size() >= 3 && straying <= band + c.division && std::abs(slope) * span_ms > band) {
        return "the weight drifted steadily by " + Amount(slope * 1000.0, c.unit) + "/s " + over +
               " (a drifting zero: empty the platform and zero the scale)";
    }
    if (spread <= band) {
        return "the indicator never reported a stable weight (its readings spread " +
               Amount(spread, c.unit) + " " + over + ")";
    }
    return "the weight never settled: its readings spread " + Amount(spread, c.unit) + " " + over +
           ", more than the band of " + Amount(band, c.unit) +
           " (something touches the platform, or it shakes)";
}

// The weighing once `w` is stable: the readings' mean to the division, stated from Min up.
Weighing Settled(const Window& w, const Scale& scale, const ScaleConfig& c, double waited_ms,
                 int readings) {
    double sum = 0;
    for (const Sample& s : w) sum += s.weight;
    const double value = std::round(sum / static_cast<double>(w.size()) / c.division) * c.division;
    Weighing out;
    out.unit = c.unit;
    out.division = c.division;
    out.settled_ms = waited_ms;
    out.readings = readings;
    out.scale = scale.Describe();
    if (value + 1e-12 >= c.min_weight) {
        out.value = value;
    } else {
        out.why_not = Amount(value, c.unit) + " is below the scale's minimum load of " +
                      Amount(c.min_weight, c.unit);
    }
    return out;
}

// Why `r` is outside the scale's range, or "".
std::string OutOfRange(const ScaleReading& r, const ScaleConfig& c) {
    if (r.overload || r.weight > c.capacity + 9 * c.division) {
        return "overload: the load is above the scale's capacity of " + Amount(c.capacity, c.unit) +
               " (nothing may lean on the platform)";
    }
    if (r.underload) {
        return "underload: the scale reads below zero (empty the platform and zero the scale)";
    }
    return "";
}

}  // namespace

WeighingClock RealWeighingClock() {
    const auto t0 = std::chrono::steady_clock::now();
    return WeighingClock{
        [t0] {
            return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        },
        [](int ms) { std::this_thread::sleep_for(std::chrono::milliseconds(ms)); }};
}

Result<Weighing> WeighStable(Scale& scale, const ScaleConfig& c, const std::atomic<bool>* cancel,
                             const WeighingClock& clock) {
    const double band = c.stable_band_divisions * c.division;
    const double t0 = clock.now_ms();
    Window window;
    int readings = 0;
    bool out_of_range = false;
    double out_of_range_since = 0.0;
    for (;;) {
        if (cancel && cancel->load()) return Error{ErrorCode::kAborted, "weighing cancelled"};
        Result<ScaleReading> r = scale.Read();
        if (!r) return r.error();
        ++readings;
        const double now = clock.now_ms();
        // Out of range for a whole stable time is the answer; a moment of it (a parcel's
        // overshoot as it is set down) is motion.
        if (const std::string why = OutOfRange(*r, c); !why.empty()) {
            if (!out_of_range) out_of_range_since = now;
            out_of_range = true;
            if (now - out_of_range_since >= c.stable_time_ms || now - t0 >= c.timeout_ms) {
                return ScaleFault(scale, why);
            }
            window.clear();
            clock.sleep_ms(c.poll_interval_ms);
            continue;
        }
        out_of_range = false;
        window.push_back({now, r->weight, r->stable});
        // The oldest reading kept is the newest one at least the stable time old.
        while (window.size() > 1 && window[1].t_ms <= now - c.stable_time_ms) window.pop_front();
        const bool long_enough = window.front().t_ms <= now - c.stable_time_ms;
        const bool flagged =
            !c.use_stable_flag ||
            std::all_of(window.begin(), window.end(), [](const Sample& s) { return s.flag; });
        if (long_enough && flagged && Spread(window) <= band + 1e-12) {
            return Settled(window, scale, c, now - t0, readings);
        }
        if (now - t0 >= c.timeout_ms) {
            return ScaleFault(scale, Unsettled(window, c, band) + "; no stable weight within " +
                                         std::to_string(c.timeout_ms) + " ms");
        }
        clock.sleep_ms(c.poll_interval_ms);
    }
}

}  // namespace boxd
