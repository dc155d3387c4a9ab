#include "pipeline/prepare_pose.h"

#include <spdlog/fmt/fmt.h>

#include "pipeline/parallel_for.h"

namespace boxd {

PreparedPose PreparePose(const std::vector<DepthImage>& frames, double depth_unit_m,
                         const MeasureConfig& config) {
    PreparedPose out;
    auto avg = AverageDepthFrames(frames, depth_unit_m, config.averaging);
    if (!avg) {
        out.error = avg.error().message;
        return out;
    }
    out.depth = RemoveFlyingPixels(*avg, config.flying_pixels);
    return out;
}

std::vector<PreparedPose> PrepareSession(const Session& session, const MeasureConfig& config) {
    std::vector<PreparedPose> prepared(session.poses.size());
    ParallelFor(static_cast<int>(prepared.size()), config.threads, [&](int k) {
        const auto i = static_cast<std::size_t>(k);
        prepared[i] = PreparePose(session.poses[i].frames, session.camera.depth_unit_m, config);
    });
    return prepared;
}

Result<std::vector<PreparedPose>> PrepareFromSource(const Session& header,
                                                    const MeasureConfig& config,
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

Result<DepthMap> UsableDepth(PreparedPose pose, std::size_t index, const RefusalConfig& refuse) {
    if (!pose.error.empty()) {
        return Error{ErrorCode::kInsufficientData, fmt::format("pose {}: {}", index, pose.error)};
    }
    const double valid = ValidFraction(pose.depth);
    if (valid < refuse.min_pose_valid_fraction) {
        return Error{ErrorCode::kInsufficientData,
                     fmt::format("pose {} has valid depth readings in only {:.1f}% of its pixels",
                                 index, 100.0 * valid)};
    }
    return std::move(pose.depth);
}

Result<std::vector<DepthMap>> UsableDepths(std::vector<PreparedPose> poses,
                                           const RefusalConfig& refuse) {
    if (poses.empty()) return Error{ErrorCode::kInsufficientData, "the session has no poses"};
    std::vector<DepthMap> depths(poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
        auto depth = UsableDepth(std::move(poses[i]), i, refuse);
        if (!depth) return depth.error();
        depths[i] = std::move(*depth);
    }
    return depths;
}

}  // namespace boxd
