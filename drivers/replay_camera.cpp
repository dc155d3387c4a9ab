// The replay depth camera.
#include "drivers/replay_camera.h"

namespace boxd {

ReplayCamera::ReplayCamera(std::shared_ptr<ReplaySource> source) : source_(std::move(source)) {}

Status ReplayCamera::Open() {
    if (!source_ || source_->session().poses.empty()) {
        return CameraError("replay camera: the session has no poses");
    }
    open_ = true;
    return OkStatus();
}

Result<DepthImage> ReplayCamera::Grab(std::chrono::milliseconds /*timeout*/) {
    if (!open_) return CameraError("replay camera: camera is not open");
    return source_->NextFrame();
}

std::string ReplayCamera::Describe() const {
    const Session& s = source_->session();
    return "replay of a " + s.source + " session, " + std::to_string(s.poses.size()) + " poses, " +
           std::to_string(s.camera.width) + "x" + std::to_string(s.camera.height);
}

}  // namespace boxd
