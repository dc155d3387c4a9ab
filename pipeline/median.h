#pragma once
// The median the pipeline's robust statistics share.

#include <algorithm>
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

}  // namespace boxd
