#include "pipeline/core/student_t.h"

#include <cmath>

namespace boxd {

double StudentT95(int dof) {
    constexpr double p = 0.975;  // the upper tail of a two-sided 95% bound
    if (dof <= 1) return std::tan(M_PI * (p - 0.5));
    if (dof == 2) return (2.0 * p - 1.0) / std::sqrt(2.0 * p * (1.0 - p));
    const double x = kNormal95, x2 = x * x, v = dof;
    const double g1 = (x2 + 1.0) * x / 4.0;
    const double g2 = ((5.0 * x2 + 16.0) * x2 + 3.0) * x / 96.0;
    const double g3 = (((3.0 * x2 + 19.0) * x2 + 17.0) * x2 - 15.0) * x / 384.0;
    const double g4 =
        ((((79.0 * x2 + 776.0) * x2 + 1482.0) * x2 - 1920.0) * x2 - 945.0) * x / 92160.0;
    return x + g1 / v + g2 / (v * v) + g3 / (v * v * v) + g4 / (v * v * v * v);
}

double WidenedForSamples(double se, int samples) {
    return samples >= 2 ? se * StudentT95(samples - 1) / kNormal95 : se;
}

}  // namespace boxd
