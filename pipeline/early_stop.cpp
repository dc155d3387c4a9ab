#include "pipeline/early_stop.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace boxd {

double WidestGapDeg(std::vector<double> angles_deg) {
    if (angles_deg.size() < 2) return 360.0;
    for (double& a : angles_deg) {
        a = std::fmod(a, 360.0);
        if (a < 0.0) a += 360.0;
    }
    std::sort(angles_deg.begin(), angles_deg.end());
    double widest = angles_deg.front() + 360.0 - angles_deg.back();
    for (std::size_t i = 1; i < angles_deg.size(); ++i) {
        widest = std::max(widest, angles_deg[i] - angles_deg[i - 1]);
    }
    return widest;
}

bool SurroundsObject(const std::vector<double>& angles_deg) {
    return WidestGapDeg(angles_deg) <= kSurroundGapDeg;
}

double DeterminingBound(const MeasurementResult& r) {
    const bool cuboid = r.status == MeasurementStatus::kOk && r.shape == "cuboid" &&
                        r.uncertainty_m && r.quality.face_flatness &&
                        *r.quality.face_flatness <= kFlatFaces;
    if (!cuboid) return std::numeric_limits<double>::infinity();
    return std::max(
        {r.uncertainty_m->length_m, r.uncertainty_m->width_m, r.uncertainty_m->height_m});
}

}  // namespace boxd
