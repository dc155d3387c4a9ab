#include "pipeline/frame_averaging.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace boxd {

namespace {

Status Bad(const std::string& field, const std::string& why) {
    return Error{ErrorCode::kInvalidConfig, field + ": " + why};
}

bool NonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

// Sessions hold at most a few dozen frames per pose; larger counts use the heap path.
constexpr std::size_t kStackReadings = 64;

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
    const std::size_t required = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::ceil(config.min_valid_fraction * n - 1e-9)));
    DepthMap out(w, h);
    std::vector<std::uint16_t> heap(n > kStackReadings ? n : 0);
    std::array<std::uint16_t, kStackReadings> stack{};
    std::uint16_t* r = n > kStackReadings ? heap.data() : stack.data();
    // The frames' pixel arrays, looked up once instead of through the vectors for every pixel.
    std::vector<const std::uint16_t*> src(n);
    for (std::size_t f = 0; f < n; ++f) src[f] = frames[f].pixels.data();
    const std::size_t count = out.z_m.size();
    for (std::size_t i = 0; i < count; ++i) {
        std::size_t k = 0;
        for (std::size_t f = 0; f < n; ++f) {
            const std::uint16_t v = src[f][i];
            if (v != 0) r[k++] = v;
        }
        if (k < required) continue;
        // Median of the valid readings (lower median for even counts: deterministic, and the
        // agreement window below is symmetric enough for it).
        if (k <= 16) {
            // Insertion sort: a handful of readings per pixel, far cheaper than nth_element.
            for (std::size_t a = 1; a < k; ++a) {
                const std::uint16_t v = r[a];
                std::size_t b = a;
                for (; b > 0 && r[b - 1] > v; --b) r[b] = r[b - 1];
                r[b] = v;
            }
        } else {
            std::nth_element(r, r + (k - 1) / 2, r + k);
        }
        const double median = r[(k - 1) / 2] * depth_unit_m;
        const double tol = config.agreement_abs_m + config.agreement_rel_per_m * median * median;
        double sum = 0.0;
        std::size_t kept = 0;
        for (std::size_t j = 0; j < k; ++j) {
            const double z = r[j] * depth_unit_m;
            if (std::abs(z - median) <= tol) {
                sum += z;
                ++kept;
            }
        }
        // No strict majority agrees: the pixel is unstable (an edge or a moving surface).
        if (kept < required || 2 * kept <= k) continue;
        out.z_m[i] = static_cast<float>(sum / static_cast<double>(kept));
    }
    return out;
}

DepthMap RemoveFlyingPixels(const DepthMap& depth, const FlyingPixelConfig& config) {
    DepthMap cur = depth;
    const int w = depth.width, h = depth.height;
    for (int pass = 0; pass < config.passes; ++pass) {
        DepthMap next = cur;
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                const float z = cur.at(x, y);
                if (z <= 0.0f) continue;
                const float tol = static_cast<float>(config.jump_abs_m + config.jump_rel * z);
                bool flying = false;
                for (int dy = -1; dy <= 1 && !flying; ++dy) {
                    const int yy = y + dy;
                    if (yy < 0 || yy >= h) continue;
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int xx = x + dx;
                        if (xx < 0 || xx >= w || (dx == 0 && dy == 0)) continue;
                        const float zn = cur.at(xx, yy);
                        if (zn > 0.0f && std::abs(zn - z) > tol) {
                            flying = true;
                            break;
                        }
                    }
                }
                if (flying) next.at(x, y) = 0.0f;
            }
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
