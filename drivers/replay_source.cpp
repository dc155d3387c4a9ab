// ReplaySource: a recorded session served back pose by pose.
#include "drivers/replay_source.h"

#include <cmath>
#include <sstream>

#include "pipeline/io/session_io.h"

namespace boxd {

namespace {
constexpr double kAngleMatchDeg = 0.01;
}

Status ReplayConfig::Validate() const {
    if (session.empty()) {
        return Error{ErrorCode::kInvalidInput, "camera.replay.session: must name a session folder"};
    }
    return OkStatus();
}

Result<std::shared_ptr<ReplaySource>> ReplaySource::Load(const std::filesystem::path& dir) {
    auto session = LoadSession(dir);
    if (!session) return session.error();
    return std::make_shared<ReplaySource>(std::move(session).value());
}

ReplaySource::ReplaySource(Session session) : session_(std::move(session)) {}

std::optional<std::size_t> ReplaySource::FindPose(double angle_deg) const {
    for (std::size_t i = 0; i < session_.poses.size(); ++i) {
        const double diff = std::remainder(angle_deg - session_.poses[i].angle_deg, 360.0);
        if (std::abs(diff) <= kAngleMatchDeg) return i;
    }
    return std::nullopt;
}

void ReplaySource::SelectPose(std::size_t pose) {
    std::lock_guard lock(mutex_);
    pose_ = pose;
    next_frame_ = 0;
}

std::size_t ReplaySource::CurrentPose() const {
    std::lock_guard lock(mutex_);
    return pose_;
}

DepthImage ReplaySource::NextFrame() {
    std::lock_guard lock(mutex_);
    const auto& frames = session_.poses[pose_].frames;
    const DepthImage& frame = frames[next_frame_ % frames.size()];
    ++next_frame_;
    return frame;
}

std::string ReplaySource::AngleList() const {
    std::ostringstream out;
    for (std::size_t i = 0; i < session_.poses.size(); ++i) {
        out << (i ? ", " : "") << session_.poses[i].angle_deg;
    }
    return out.str();
}

std::size_t ReplaySource::MinFramesPerPose() const {
    std::size_t n = 0;
    for (const auto& pose : session_.poses) {
        n = (n == 0) ? pose.frames.size() : std::min(n, pose.frames.size());
    }
    return n;
}

}  // namespace boxd
