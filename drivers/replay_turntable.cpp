// The replay turntable.
#include "drivers/replay_turntable.h"

#include <sstream>

namespace boxd {

ReplayTurntable::ReplayTurntable(std::shared_ptr<ReplaySource> source)
    : source_(std::move(source)) {}

Status ReplayTurntable::Home() {
    if (stop_requested_.load()) return Error{ErrorCode::kTurntableError, "replay: stop requested"};
    angle_deg_ = 0.0;
    homed_ = true;
    if (auto pose = source_->FindPose(0.0)) source_->SelectPose(*pose);
    return OkStatus();
}

Status ReplayTurntable::MoveTo(double angle_deg) {
    if (stop_requested_.load()) {
        Stop().ok();
        return Error{ErrorCode::kTurntableError, "replay: stop requested"};
    }
    const auto pose = source_->FindPose(angle_deg);
    if (!pose) {
        std::ostringstream msg;
        msg << "replay: the session has no pose at " << angle_deg
            << " deg (recorded angles: " << source_->AngleList() << ")";
        return Error{ErrorCode::kTurntableError, msg.str()};
    }
    source_->SelectPose(*pose);
    angle_deg_ = angle_deg;
    homed_ = true;
    return OkStatus();
}

Status ReplayTurntable::Stop() {
    ++stop_count_;
    return OkStatus();
}

Result<TurntableState> ReplayTurntable::State() {
    TurntableState state;
    state.homed = homed_;
    state.in_position = true;
    state.angle_deg = angle_deg_;
    return state;
}

std::string ReplayTurntable::Describe() const {
    return "replay turntable, " + std::to_string(source_->session().poses.size()) +
           " recorded poses";
}

}  // namespace boxd
