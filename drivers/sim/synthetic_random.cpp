#include "drivers/sim/synthetic_random.h"

#include <cmath>

namespace boxd::synthetic_random {

namespace {

// Inverse of the standard normal CDF Phi(x) = erfc(-x / sqrt 2) / 2 by Newton's method; the
// targets increase, so each solve starts from the previous answer and needs few steps.
NormalQuantileTable BuildQuantileTable() {
    constexpr int n = 1 << kNormalQuantileBits;
    NormalQuantileTable table{};
    auto phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
    const double inv_sqrt_2pi = 1.0 / std::sqrt(2.0 * M_PI);
    // Fill the upper half and mirror it: the quantiles are symmetric about 0.
    double x = 0.0;
    for (int q = n / 2; q < n; ++q) {
        const double p = (q + 0.5) / n;
        for (int it = 0; it < 50; ++it) {
            const double step = (phi(x) - p) / (inv_sqrt_2pi * std::exp(-0.5 * x * x));
            x -= step;
            if (std::abs(step) < 1e-12) break;
        }
        table[static_cast<std::size_t>(q)] = static_cast<float>(x);
        table[static_cast<std::size_t>(n - 1 - q)] = static_cast<float>(-x);
    }
    return table;
}

}  // namespace

const NormalQuantileTable& NormalQuantiles() {
    static const NormalQuantileTable table = BuildQuantileTable();
    return table;
}

}  // namespace boxd::synthetic_random
