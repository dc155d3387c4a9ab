#pragma once
// ReplaySource: a recorded session served back as a station — the replay camera hands out the
// frames of the pose the replay turntable last moved to. Both drivers share one source.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "pipeline/core/result.h"
#include "pipeline/io/session.h"

namespace boxd {

// The `camera.replay:` section.
struct ReplayConfig {
    std::string session;  // folder of a boxd.session/1 session

    // Returns an error naming the first invalid field ("camera.replay.<field>: ..."), or Ok.
    Status Validate() const;
};

class ReplaySource {
public:
    // Returns the source of the session in `dir` (loaded and validated with LoadSession), or
    // its INVALID_SESSION error.
    static Result<std::shared_ptr<ReplaySource>> Load(const std::filesystem::path& dir);
    explicit ReplaySource(Session session);

    const Session& session() const { return session_; }

    // Returns the index of the pose recorded at `angle_deg` (same angle modulo 360 within
    // 0.01°), or nothing.
    std::optional<std::size_t> FindPose(double angle_deg) const;
    // Makes `pose` the current pose; its frames are served from the first one again.
    void SelectPose(std::size_t pose);
    // Returns the current pose index.
    std::size_t CurrentPose() const;
    // Returns the next frame of the current pose (cycling through its frames).
    DepthImage NextFrame();
    // Returns "0, 20, 40" (the recorded angles in degrees).
    std::string AngleList() const;
    // Returns the smallest number of frames any pose has.
    std::size_t MinFramesPerPose() const;

private:
    Session session_;
    mutable std::mutex mutex_;
    std::size_t pose_ = 0;
    std::size_t next_frame_ = 0;
};

}  // namespace boxd
