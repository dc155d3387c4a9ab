#include "pipeline/views/depth_rounding.h"

#include <algorithm>
#include <cmath>

namespace boxd {

void RoundingEvidence::Add(double raw_fitted_depth_m, double gain, double residual_m) {
    raw_depths_m.push_back(raw_fitted_depth_m);
    gains.push_back(gain);
    squares_ += (residual_m / gain) * (residual_m / gain);
}

void RoundingEvidence::AddAlongRay(const Eigen::Vector3d& ray, const Eigen::Vector3d& axis,
                                   const Eigen::Vector3d& normal, double camera_height_m,
                                   double residual_m, const StationCalibration& calibration) {
    const double depth = ray.dot(axis), across = normal.dot(ray);
    if (!(depth > 0.0) || across == 0.0) return;
    Add(calibration.RawDepth(-camera_height_m / across * depth), std::abs(across) / depth,
        residual_m);
}

void RoundingEvidence::Finish() {
    if (!gains.empty()) depth_scatter_m = std::sqrt(squares_ / static_cast<double>(gains.size()));
    Thin(kRoundingReadings);
}

void RoundingEvidence::Thin(std::size_t max_readings) {
    const std::size_t n = raw_depths_m.size();
    if (n <= max_readings || max_readings == 0) return;
    std::vector<double> depths, weights;
    depths.reserve(max_readings);
    weights.reserve(max_readings);
    for (std::size_t j = 0; j < max_readings; ++j) {
        const std::size_t i = j * n / max_readings;
        depths.push_back(raw_depths_m[i]);
        weights.push_back(gains[i]);
    }
    raw_depths_m = std::move(depths);
    gains = std::move(weights);
}

double SharedRoundingSigma(const RoundingEvidence& evidence, double unit_m) {
    const std::size_t n = std::min(evidence.raw_depths_m.size(), evidence.gains.size());
    if (n == 0 || !(unit_m > 0.0)) return 0.0;
    const double scatter_sq = evidence.depth_scatter_m * evidence.depth_scatter_m;
    const double noise_sq = std::max(0.0, scatter_sq - unit_m * unit_m / 12.0);
    const double damping = 4.0 * M_PI * M_PI * noise_sq / (unit_m * unit_m);
    // The readings' gains by their phase within the unit, in kBins bins (a thousandth of the unit
    // apart, far finer than anything the sum resolves): the sum then costs kBins per term,
    // whatever the readings' number, and can take terms up to kBins / 2, where depths that repeat
    // the unit's fraction (a stride of 1.37 units repeats after 100 readings) still add.
    constexpr int kBins = 1024;
    std::vector<double> binned(kBins, 0.0);
    double gain_sq = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const double x = evidence.raw_depths_m[i] / unit_m;
        const int b = std::min(kBins - 1, static_cast<int>((x - std::floor(x)) * kBins));
        binned[static_cast<std::size_t>(b)] += evidence.gains[i];
        gain_sq += evidence.gains[i] * evidence.gains[i];
    }
    // Term k of bin b turns by pi k (2 b + 1) / kBins: a table of the 2 kBins angles pi m / kBins.
    std::vector<double> cosine(2 * kBins), sine(2 * kBins);
    for (int m = 0; m < 2 * kBins; ++m) {
        cosine[static_cast<std::size_t>(m)] = std::cos(M_PI * m / kBins);
        sine[static_cast<std::size_t>(m)] = std::sin(M_PI * m / kBins);
    }
    const auto count = static_cast<double>(n);
    double sum = 0.0;
    int k = 1;
    for (; k <= kBins / 2; ++k) {
        if (damping * k * k > 50.0) break;  // the rest is below e^-50 of the first term
        double re = 0.0, im = 0.0;
        for (int b = 0; b < kBins; ++b) {
            if (binned[static_cast<std::size_t>(b)] == 0.0) continue;
            const auto m = static_cast<std::size_t>((k * (2 * b + 1)) % (2 * kBins));
            re += binned[static_cast<std::size_t>(b)] * cosine[m];
            im += binned[static_cast<std::size_t>(b)] * sine[m];
        }
        sum += std::exp(-damping * k * k) * (re * re + im * im) / (count * count) /
               (static_cast<double>(k) * k);
    }
    // Without noise the terms beyond are taken at what readings at random phases give them;
    // their 1 / k^2 sums to about 1 / k.
    if (k > kBins / 2) sum += std::exp(-damping * k * k) * gain_sq / (count * count) / k;
    return unit_m / (M_SQRT2 * M_PI) * std::sqrt(sum);
}

double OneDepthRoundingSigma(double unit_m, double noise_m) {
    if (!(unit_m > 0.0)) return 0.0;
    return unit_m / std::sqrt(12.0) *
           std::exp(-2.0 * M_PI * M_PI * noise_m * noise_m / (unit_m * unit_m));
}

}  // namespace boxd
