#include "pipeline/core/kinect_disparity.h"

namespace boxd {

const KinectDepthTable& KinectDisparityDepths() {
    static const KinectDepthTable table = [] {
        KinectDepthTable t{};
        for (int raw = 0; raw <= kKinectMaxRawDisparity; ++raw) {
            const double inverse = raw * kKinectDisparityScale + kKinectDisparityOffset;
            t[static_cast<std::size_t>(raw)] = inverse > 0.0 ? 1.0 / inverse : 0.0;
        }
        return t;
    }();
    return table;
}

}  // namespace boxd
