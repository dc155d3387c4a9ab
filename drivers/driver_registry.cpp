// The driver registry.
#include "drivers/driver_registry.h"

#include <spdlog/spdlog.h>

#include "drivers/freenect_camera.h"
#include "drivers/openni2_camera.h"
#include "drivers/replay_camera.h"
#include "drivers/replay_turntable.h"
#include "drivers/sim/simulated_camera.h"

namespace boxd {

TurntableDirection ParseDirection(const std::string& direction) {
    return direction == "cw" ? TurntableDirection::kCw : TurntableDirection::kCcw;
}

Result<std::unique_ptr<DepthCamera>> MakeDepthCamera(const CameraConfig& config,
                                                     Turntable* turntable,
                                                     TurntableDirection direction) {
    if (auto st = config.Validate(); !st) return st.error();
    if (config.driver == "openni2") {
        return std::unique_ptr<DepthCamera>(std::make_unique<OpenNi2Camera>(
            config.openni2, config.intrinsics, config.depth_unit_m));
    }
    if (config.driver == "freenect") {
        return std::unique_ptr<DepthCamera>(std::make_unique<FreenectCamera>(
            config.freenect, config.intrinsics, config.depth_unit_m));
    }
    if (config.driver == "simulated") {
        if (!turntable) return CameraError("simulated camera: needs the station's turntable");
        // The renderer turns the table counter-clockwise for positive angles; a clockwise
        // station's positive angles are clockwise turns.
        const double sign = direction == TurntableDirection::kCw ? -1.0 : 1.0;
        AngleSource angle = [turntable, sign]() -> Result<double> {
            auto a = turntable->CurrentAngleDeg();
            if (!a) return a.error();
            return sign * *a;
        };
        return std::unique_ptr<DepthCamera>(
            std::make_unique<SimulatedCamera>(config.simulated, std::move(angle)));
    }
    auto source = ReplaySource::Load(config.replay.session);
    if (!source) return source.error();
    return std::unique_ptr<DepthCamera>(std::make_unique<ReplayCamera>(*source));
}

Result<StationDevices> OpenStation(const StationConfig& config, const std::atomic<bool>* cancel) {
    StationDevices devices;
    devices.capture = config.capture;
    devices.calibrated = config.calibration.has_value();
    if (config.calibration) devices.station.calibration = *config.calibration;

    if (config.camera.driver == "replay") {
        if (auto st = config.camera.Validate(); !st) return st.error();
        auto source = ReplaySource::Load(config.camera.replay.session);
        if (!source) return source.error();
        const Session& session = (*source)->session();
        devices.turntable = std::make_unique<ReplayTurntable>(*source);
        devices.camera = std::make_unique<ReplayCamera>(*source);
        devices.station.direction = session.direction;
        if (!config.calibration) {
            devices.station.calibration = session.calibration;
            devices.calibrated = true;
        }
        // A replay serves the session as recorded: its angles, its frames, nothing dropped.
        devices.capture.angles_deg.clear();
        for (const auto& pose : session.poses) devices.capture.angles_deg.push_back(pose.angle_deg);
        devices.capture.frames_per_pose = static_cast<int>((*source)->MinFramesPerPose());
        devices.capture.drop_frames = 0;
        devices.capture.settle_ms = 0;
        spdlog::info("replay station: {} poses, {} frames each", session.poses.size(),
                     devices.capture.frames_per_pose);
    } else {
        devices.station.direction = ParseDirection(config.turntable.direction);
        auto turntable = MakeTurntable(config.turntable, cancel);
        if (!turntable) return turntable.error();
        devices.turntable = std::move(turntable).value();
        auto camera =
            MakeDepthCamera(config.camera, devices.turntable.get(), devices.station.direction);
        if (!camera) return camera.error();
        devices.camera = std::move(camera).value();
    }
    if (auto st = devices.camera->Open(); !st) return st.error();
    if (config.scale.enabled()) {
        auto scale = MakeScale(config.scale);
        if (!scale) return scale.error();
        devices.scale = std::move(scale).value();
        spdlog::info("scale: {}", devices.scale->Describe());
    }
    spdlog::info("turntable: {}", devices.turntable->Describe());
    spdlog::info("camera: {}", devices.camera->Describe());
    return devices;
}

}  // namespace boxd
