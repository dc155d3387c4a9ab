#include "pipeline/frames/frame_averaging.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "pipeline/frames/depth_levels.h"

namespace boxd {

namespace {

Status Bad(const std::string& field, const std::string& why) {
    return Error{ErrorCode::kInvalidConfig, field + ": " + why};
}

bool NonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

// What averaging needs for every pixel of a pose.
struct AveragingPass {
    std::vector<const std::uint16_t*> src;  // the frames' pixel arrays
    std::size_t required = 1;               // valid readings a pixel needs
    // Twice the agreement window (raw units) by the lower median reading: the median of an even
    // count lies half-way between two readings, so the readings are compared doubled.
    std::vector<std::uint32_t> window;
    // When the readings come in levels, each recorded value's depth in 1/kFixedScale raw units,
    // so that sums stay integer (without levels, a value's depth is itself times kFixedScale).
    bool levels = false;
    std::vector<std::int32_t> fixed;
    double unit = 0.001;
};

// 8 bits below the raw unit: 8 frames of 16-bit values still sum within 31 bits, and a level's
// depth is kept to 1/256 of the unit (4 microns for 1 mm).
constexpr std::int32_t kFixedBits = 8;
constexpr double kFixedScale = 1 << kFixedBits;
constexpr std::size_t kValues = 65536;  // every 16-bit reading

float FixedMean(std::uint64_t sum, std::uint64_t kept, double unit) {
    return static_cast<float>(static_cast<double>(sum) * (unit / kFixedScale) /
                              static_cast<double>(kept));
}

// How far (doubled raw units) a reading may lie from twice the median of `valid` readings whose
// lower middle one is `lower`: twice the window, but for two readings alone, which must lie within
// the window of each other (see AverageAll).
inline std::uint32_t AgreementTolerance(const AveragingPass& pass, std::uint32_t lower,
                                        std::uint32_t valid) {
    return pass.window[lower] >> (valid == 2 ? 1 : 0);
}

// Averages the pass's N frames into *out, pixel by pixel (a refused pixel stays 0). The rule:
// the median of the valid readings (of an even count, the mean of the middle two), then the mean
// of those within its agreement window (the window of the lower middle reading's depth), when
// they are enough and a strict majority. The lower middle reading alone would centre the window
// nearer than the readings' middle, and where the noise is as wide as the window (a surface
// seen at grazing incidence) keep more of the near readings than of the far ones: at four frames
// a pose of twice a Kinect's noise, a box's sides read 0.4 mm out. Two readings alone agree when
// they lie within the window of each other, not of their mean: no third says which one a wider
// gap belongs to, and their mean would be a reading of neither (at two frames a pose, a
// time-of-flight camera's mixed pixels at a frustum's top, averaged with the top, read it 2.9 mm
// high).
// N fixed at compile time, and nothing branches on the readings (they are noise: any branch on
// them would be mispredicted about half the time), so the median loop vectorises. A reading
// of 0 (no return) ranks above every valid one: the middle two of the k valid readings are
// those with (k - 1) / 2 and k / 2 readings before them (ties broken by frame order).
// `median` holds their sum, twice the median.
// kLevels: the readings are read at their levels (pass.fixed), which the compiler cannot gather
// as fast as it shifts the values themselves.
template <std::size_t N, bool kLevels>
void AverageAll(const AveragingPass& pass, DepthMap* out) {
    constexpr std::size_t kBlock = 1024;
    constexpr std::int32_t kNone = 0x10000;  // above every 16-bit reading
    std::array<std::uint32_t, kBlock> median{}, lower_median{}, valid{}, tol{}, sums{}, agreeing{};
    const std::size_t count = out->z_m.size();
    for (std::size_t start = 0; start < count; start += kBlock) {
        const std::size_t len = std::min(kBlock, count - start);
        // Signed 32-bit lanes: SSE2 compares those directly (readings fit in 17 bits).
        for (std::size_t p = 0; p < len; ++p) {
            std::array<std::int32_t, N> r{};
            std::int32_t k = 0;
            for (std::size_t f = 0; f < N; ++f) {
                const std::int32_t v = pass.src[f][start + p];
                k += v != 0 ? 1 : 0;
                r[f] = v != 0 ? v : kNone;
            }
            const std::int32_t lo = (k > 0 ? k - 1 : 0) / 2, hi = k / 2;
            std::int32_t lower = 0, upper = 0;
            for (std::size_t a = 0; a < N; ++a) {
                std::int32_t rank = 0;
                for (std::size_t b = 0; b < N; ++b) {
                    rank += (r[b] < r[a] || (r[b] == r[a] && b < a)) ? 1 : 0;
                }
                lower += rank == lo ? r[a] : 0;
                upper += rank == hi ? r[a] : 0;
            }
            median[p] = static_cast<std::uint32_t>(lower + upper);
            lower_median[p] = static_cast<std::uint32_t>(lower);
            valid[p] = static_cast<std::uint32_t>(k);
        }
        // The agreement windows (a table lookup; a pixel without readings looks up the entry
        // past the 16-bit range), then each pixel's agreeing readings, again without a branch.
        for (std::size_t p = 0; p < len; ++p) {
            tol[p] = AgreementTolerance(pass, lower_median[p], valid[p]);
        }
        for (std::size_t p = 0; p < len; ++p) {
            const auto med = static_cast<std::int32_t>(median[p]);
            const auto window = static_cast<std::int32_t>(tol[p]);
            std::int32_t sum = 0, kept = 0;
            for (std::size_t f = 0; f < N; ++f) {
                const std::int32_t v = pass.src[f][start + p];
                const std::int32_t d = 2 * v > med ? 2 * v - med : med - 2 * v;
                const bool agrees = v != 0 && d <= window;
                const std::int32_t depth =
                    kLevels ? pass.fixed[static_cast<std::size_t>(v)] : v << kFixedBits;
                sum += agrees ? depth : 0;
                kept += agrees ? 1 : 0;
            }
            sums[p] = static_cast<std::uint32_t>(sum);
            agreeing[p] = static_cast<std::uint32_t>(kept);
        }
        for (std::size_t p = 0; p < len; ++p) {
            // Too few readings, too few agreeing, or no strict majority (the pixel is unstable:
            // an edge or a moving surface).
            const std::uint32_t kept = agreeing[p];
            if (valid[p] < pass.required || kept < pass.required || 2 * kept <= valid[p]) continue;
            out->z_m[start + p] = FixedMean(sums[p], kept, pass.unit);
        }
    }
}

// AverageAll for the pass's kind of readings.
template <std::size_t N>
void AverageWith(const AveragingPass& pass, DepthMap* out) {
    if (pass.levels) {
        AverageAll<N, true>(pass, out);
    } else {
        AverageAll<N, false>(pass, out);
    }
}

// Any number of frames: the same rule through a sort of the valid readings.
void AveragePixelAnyCount(const AveragingPass& pass, std::size_t i, std::uint16_t* r, float* out) {
    std::size_t k = 0;
    for (const std::uint16_t* frame : pass.src) {
        if (frame[i] != 0) r[k++] = frame[i];
    }
    if (k < pass.required) return;
    const std::size_t m = (k - 1) / 2;
    std::nth_element(r, r + m, r + k);
    const std::uint32_t lower = r[m];
    const std::uint32_t upper = k % 2 == 1 ? lower : *std::min_element(r + m + 1, r + k);
    const std::uint32_t median = lower + upper;  // twice the median
    const std::uint32_t tol = AgreementTolerance(pass, lower, static_cast<std::uint32_t>(k));
    std::uint64_t sum = 0;
    std::size_t kept = 0;
    for (std::size_t j = 0; j < k; ++j) {
        const std::uint32_t v = 2 * static_cast<std::uint32_t>(r[j]);
        if ((v > median ? v - median : median - v) <= tol) {
            sum += pass.levels ? static_cast<std::uint64_t>(pass.fixed[r[j]])
                               : static_cast<std::uint64_t>(r[j]) << kFixedBits;
            ++kept;
        }
    }
    if (kept < pass.required || 2 * kept <= k) return;
    *out = FixedMean(sum, kept, pass.unit);
}

}  // namespace

Status AveragingConfig::Validate() const {
    if (!std::isfinite(min_valid_fraction) || min_valid_fraction <= 0.0 ||
        min_valid_fraction > 1.0) {
        return Bad("averaging.min_valid_fraction", "must be in (0, 1]");
    }
    if (!NonNegative(agreement_abs_m)) return Bad("averaging.agreement_abs_m", "must be >= 0");
    if (!NonNegative(agreement_rel_per_m)) {
        return Bad("averaging.agreement_rel_per_m", "must be >= 0");
    }
    return OkStatus();
}

Status FlyingPixelConfig::Validate() const {
    if (!NonNegative(jump_abs_m)) return Bad("flying_pixels.jump_abs_m", "must be >= 0");
    if (!NonNegative(jump_rel)) return Bad("flying_pixels.jump_rel", "must be >= 0");
    if (passes < 0 || passes > 5) return Bad("flying_pixels.passes", "must be in 0..5");
    return OkStatus();
}

namespace {

// The recorded values' depths: their levels' where the readings come in levels
// (depth_levels.h). Every value keeps its own depth, but for those of the span the levels were
// found in (a value the histogram's stride passed over may lie outside it).
void ReadLevels(const std::vector<DepthImage>& frames, double depth_unit_m, AveragingPass* pass) {
    const auto levels = FindDepthLevels(frames, depth_unit_m);
    if (!levels) {
        spdlog::debug("depth levels: none (the recorded values are the depths)");
        return;
    }
    spdlog::debug("depth levels: {:.9f} per m apart, {} values fitted, {:.2f}% on a level",
                  levels->spacing_per_m, levels->fitted, 100.0 * levels->on_level);
    pass->levels = true;
    pass->fixed.resize(kValues);
    for (std::size_t v = 0; v < pass->fixed.size(); ++v) {
        pass->fixed[v] = static_cast<std::int32_t>(v) << kFixedBits;
    }
    for (int v = levels->lowest; v <= levels->highest; ++v) {
        pass->fixed[static_cast<std::size_t>(v)] = static_cast<std::int32_t>(
            std::lround(RecordedDepth(*levels, v, depth_unit_m) / depth_unit_m * kFixedScale));
    }
}

// The agreement window of SPEC section 7's sensor model grows with depth: twice the window,
// looked up per raw lower median reading (in raw units) instead of computed in metres for every
// pixel. The last entry is a pixel without readings (never used).
std::vector<std::uint32_t> AgreementWindows(const AveragingConfig& config, double depth_unit_m) {
    std::vector<std::uint32_t> window(kValues + 1);
    for (std::size_t v = 0; v < window.size(); ++v) {
        const double z = static_cast<double>(v) * depth_unit_m;
        const double tol = config.agreement_abs_m + config.agreement_rel_per_m * z * z;
        // Truncation is the floor here (the window is never negative), and it vectorises.
        window[v] = static_cast<std::uint32_t>(std::min(131070.0, 2.0 * tol / depth_unit_m));
    }
    return window;
}

// Averages every pixel of `pass`'s `n` frames into `out`: a loop unrolled for each count up to
// eight frames.
void AverageFrames(const AveragingPass& pass, std::size_t n, DepthMap* out) {
    switch (n) {
        case 1:
            return AverageWith<1>(pass, out);
        case 2:
            return AverageWith<2>(pass, out);
        case 3:
            return AverageWith<3>(pass, out);
        case 4:
            return AverageWith<4>(pass, out);
        case 5:
            return AverageWith<5>(pass, out);
        case 6:
            return AverageWith<6>(pass, out);
        case 7:
            return AverageWith<7>(pass, out);
        case 8:
            return AverageWith<8>(pass, out);
        default: {
            std::vector<std::uint16_t> r(n);
            for (std::size_t i = 0; i < out->z_m.size(); ++i) {
                AveragePixelAnyCount(pass, i, r.data(), &out->z_m[i]);
            }
        }
    }
}

}  // namespace

Result<DepthMap> AverageDepthFrames(const std::vector<DepthImage>& frames, double depth_unit_m,
                                    const AveragingConfig& config) {
    if (frames.empty()) return Error{ErrorCode::kInsufficientData, "no frames to average"};
    const int w = frames[0].width, h = frames[0].height;
    for (const DepthImage& f : frames) {
        if (f.width != w || f.height != h ||
            f.pixels.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h)) {
            return Error{ErrorCode::kInsufficientData, "frames of one pose differ in size"};
        }
    }
    const std::size_t n = frames.size();
    AveragingPass pass;
    pass.required = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::ceil(config.min_valid_fraction * n - 1e-9)));
    pass.unit = depth_unit_m;
    for (const DepthImage& f : frames) pass.src.push_back(f.pixels.data());
    if (config.depth_levels) {
        ReadLevels(frames, depth_unit_m, &pass);
    } else {
        spdlog::debug("depth levels: none (the recorded values are the depths)");
    }
    pass.window = AgreementWindows(config, depth_unit_m);
    DepthMap out(w, h);
    AverageFrames(pass, n, &out);
    return out;
}

namespace {

// 1 when the neighbour reading zn is valid and jumps from z by more than tol, else 0. Bitwise,
// not short-circuit: the loop that ors these has no branch and vectorises.
inline int Jump(float zn, float z, float tol) {
    return static_cast<int>(zn > 0.0f) & static_cast<int>(std::abs(zn - z) > tol);
}

}  // namespace

DepthMap RemoveFlyingPixels(const DepthMap& depth, const FlyingPixelConfig& config) {
    DepthMap cur = depth;
    const int w = depth.width, h = depth.height;
    const auto abs_m = static_cast<float>(config.jump_abs_m);
    const auto rel = static_cast<float>(config.jump_rel);
    for (int pass = 0; pass < config.passes; ++pass) {
        DepthMap next = cur;
        for (int y = 0; y < h; ++y) {
            // The rows around y (those outside the image are left out).
            std::array<const float*, 3> rows{};
            int nrows = 0;
            for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
                rows[static_cast<std::size_t>(nrows++)] =
                    cur.z_m.data() + static_cast<std::size_t>(yy) * static_cast<std::size_t>(w);
            }
            const float* row = cur.z_m.data() + static_cast<std::size_t>(y) * w;
            float* out = next.z_m.data() + static_cast<std::size_t>(y) * w;
            // Pixel x against its neighbours in the rows and columns the image has (the pixel
            // itself never differs from itself).
            auto bounded = [&](int x) {
                const float z = row[x];
                const float tol = abs_m + rel * z;
                int jumps = 0;
                for (int r = 0; r < nrows; ++r) {
                    for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
                        jumps |= Jump(rows[static_cast<std::size_t>(r)][xx], z, tol);
                    }
                }
                if (z > 0.0f && jumps != 0) out[x] = 0.0f;
            };
            if (nrows < 3 || w <= 2) {
                for (int x = 0; x < w; ++x) bounded(x);
                continue;
            }
            // Inside the image all eight neighbours exist: no bound to check, no branch on the
            // readings, and the loop vectorises. The first and last columns are bounded.
            const float* up = rows[0];
            const float* down = rows[2];
            for (int x = 1; x < w - 1; ++x) {
                const float z = row[x];
                const float tol = abs_m + rel * z;
                const int jumps = Jump(up[x - 1], z, tol) | Jump(up[x], z, tol) |
                                  Jump(up[x + 1], z, tol) | Jump(row[x - 1], z, tol) |
                                  Jump(row[x + 1], z, tol) | Jump(down[x - 1], z, tol) |
                                  Jump(down[x], z, tol) | Jump(down[x + 1], z, tol);
                out[x] = (static_cast<int>(z > 0.0f) & jumps) != 0 ? 0.0f : z;
            }
            bounded(0);
            bounded(w - 1);
        }
        cur = std::move(next);
    }
    return cur;
}

double ValidFraction(const DepthMap& depth) {
    if (depth.z_m.empty()) return 0.0;
    const auto valid =
        std::count_if(depth.z_m.begin(), depth.z_m.end(), [](float z) { return z > 0.0f; });
    return static_cast<double>(valid) / static_cast<double>(depth.z_m.size());
}

}  // namespace boxd
