#include "pipeline/frames/prepare_pose.h"

#include <spdlog/fmt/fmt.h>

#include "pipeline/core/parallel_for.h"

namespace boxd {

PreparedPose PreparePose(const std::vector<DepthImage>& frames, double depth_unit_m,
                         const FrameConfig& config) {
    PreparedPose out;
    auto avg = AverageDepthFrames(frames, depth_unit_m, config.averaging);
    if (!avg) {
        out.error = avg.error().message;
        return out;
    }
    out.depth = RemoveFlyingPixels(
        RemoveGrownEdges(*avg, config.edge_growth_px, config.flying_pixels), config.flying_pixels);
    return out;
}

std::vector<PreparedPose> PrepareSession(const Session& session, const FrameConfig& config) {
    std::vector<PreparedPose> prepared(session.poses.size());
    ParallelFor(static_cast<int>(prepared.size()), config.threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        prepared[i] = PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config);
    });
    return prepared;
}

Result<std::vector<PreparedPose>> PrepareFromSource(const Session& header,
                                                    const FrameConfig& config,
                                                    const PoseFrameSource& frames) {
    std::vector<PreparedPose> prepared(header.poses.size());
    std::vector<std::optional<Error>> errors(header.poses.size());
    ParallelFor(static_cast<int>(prepared.size()), config.threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        auto loaded = frames(i);
        if (!loaded) {
            errors[i] = loaded.error();
            return;
        }
        prepared[i] = PreparePose(*loaded, header.camera.depth_unit_m, config);
    });
    for (const auto& e : errors) {
        if (e) return *e;
    }
    return prepared;
}

}  // namespace boxd
