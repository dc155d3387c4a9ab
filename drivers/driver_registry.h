#pragma once
// The driver registry: builds the devices a station config names (gpsd style: one small
// interface per device kind, the implementation picked by a config string).
//   camera.driver: openni2 | freenect | simulated | replay
//   turntable.driver: modbus-tcp | modbus-rtu | simulated (MakeTurntable); a replay camera
//   brings its own replay turntable and the turntable section is not used.
//   scale.driver: none | modbus-tcp | modbus-rtu | simulated (MakeScale).

#include <atomic>
#include <memory>

#include "drivers/depth_camera.h"
#include "drivers/scale.h"
#include "drivers/station_config.h"
#include "drivers/turntable.h"

namespace boxd {

// The devices of one station, ready to capture.
struct StationDevices {
    // Declared before the camera: the simulated camera reads this turntable's angle, so the
    // camera is destroyed first.
    std::unique_ptr<Turntable> turntable;
    std::unique_ptr<DepthCamera> camera;
    std::unique_ptr<Scale> scale;  // null when the station has none
    // The config's capture settings; for a replay station the session's angles and frame count.
    CaptureConfig capture;
    // What goes into captured sessions (config calibration; for replay without one, the
    // session's).
    CaptureStation station;
    bool calibrated = false;  // false when the config carries no calibration
};

// Returns the camera `config.driver` names (not yet opened). `turntable` is the table whose
// reported angle the simulated camera renders at (it must outlive the camera); `direction` is
// the turntable's.
Result<std::unique_ptr<DepthCamera>> MakeDepthCamera(const CameraConfig& config,
                                                     Turntable* turntable,
                                                     TurntableDirection direction);

// Returns the turntable (connected), the camera (opened) and the scale (connected, if any) of
// `config`, or the first TURNTABLE_ERROR / CAMERA_ERROR / SCALE_ERROR / INVALID_SESSION error.
// Setting `*cancel` abandons a wait for a device to come up (the simulated drive's launch) with an
// ABORTED error.
Result<StationDevices> OpenStation(const StationConfig& config,
                                   const std::atomic<bool>* cancel = nullptr);

// Returns the direction a `turntable.direction` string names ("cw" or else ccw).
TurntableDirection ParseDirection(const std::string& direction);

}  // namespace boxd
