#pragma once
// The replay depth camera: serves a recorded session's frames, pose by pose, as the replay
// turntable (replay_turntable.h) selects the pose.

#include <memory>

#include "drivers/depth_camera.h"
#include "drivers/replay_source.h"

namespace boxd {

class ReplayCamera : public DepthCamera {
public:
    explicit ReplayCamera(std::shared_ptr<ReplaySource> source);

    Status Open() override;
    CameraIntrinsics Intrinsics() const override { return source_->session().camera; }
    // Returns the next recorded frame of the current pose.
    Result<DepthImage> Grab(std::chrono::milliseconds timeout) override;
    void Close() override { open_ = false; }
    // The session's own source ("openni2", "synthetic", ...), prefixed "replay:".
    std::string SourceName() const override { return "replay:" + source_->session().source; }
    std::string Describe() const override;

private:
    std::shared_ptr<ReplaySource> source_;
    bool open_ = false;
};

}  // namespace boxd
