#pragma once
// Core: The median and quantiles the pipeline's robust statistics share.

#include <algorithm>
#include <limits>
#include <vector>

namespace boxd {

// Returns the upper median of `values` (the middle one, or the upper of the two middle ones),
// 0 when there are none.
inline double Median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
}

// Returns the element of rank floor(p (n - 1)) of `values` (0 <= p <= 1), NaN when there are
// none: the p-quantile without interpolation.
inline double Quantile(std::vector<double> values, double p) {
    if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
    const auto at =
        values.begin() + static_cast<std::ptrdiff_t>(p * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), at, values.end());
    return *at;
}

}  // namespace boxd
