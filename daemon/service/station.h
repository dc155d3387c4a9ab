#pragma once
// Station: what the service loop drives — the turntable, the depth camera and the measurement
// pipeline behind one small interface, so the loop, the API and the store are independent of the
// drivers (and testable with a station of the test's own).

#include <atomic>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "calibration/station_calibrator.h"
#include "daemon/service/measurement_store.h"
#include "drivers/depth_camera.h"
#include "pipeline/core/result.h"
#include "pipeline/core/station_calibration.h"
#include "pipeline/io/measurement.h"
#include "pipeline/io/session.h"

namespace boxd {

// Where a running measurement is: pose k of N while capturing, then the processing stage.
struct JobProgress {
    std::string stage;  // "capture" | "processing"
    int pose = 0;       // poses done so far
    int poses = 0;      // poses in the session
};

// What one measurement run gets from the service.
struct JobContext {
    std::string id;                             // "m-000042"
    std::filesystem::path scratch_dir;          // empty folder for the run's files
    bool keep_session = false;                  // also leave the captured session in scratch_dir
    const std::atomic<bool>* cancel = nullptr;  // set when the run must stop (SIGTERM)
    std::function<void(const JobProgress&)> progress;  // may be called from the run's thread

    bool cancelled() const { return cancel != nullptr && cancel->load(); }
};

// What a run hands back: the result (id and timestamps are the service's) and its files.
struct JobOutput {
    MeasurementResult result;
    MeasurementFiles files;  // paths inside the scratch folder, moved into the store
};

// One device of the station.
struct DeviceState {
    std::string driver;       // the config's driver name ("modbus-tcp", "simulated", ...)
    std::string description;  // what the opened device says it is; empty until it was opened
    bool ok = false;          // open, and no device error since
    std::optional<CameraTilt> tilt;  // the camera's accelerometer (a Kinect's), when it has one
};

// The devices' description and health (GET /v1/status "devices").
struct DeviceHealth {
    DeviceState turntable;
    DeviceState camera;
    std::optional<DeviceState> scale;  // a station with a scale
    std::optional<Error> error;        // the last device error; a successful Open() clears it
};

// The calibration in force (GET /v1/calibration).
struct CalibrationInForce {
    std::optional<StationCalibration> calibration;  // nullopt: the station is not calibrated
    std::filesystem::path source;                   // the file the calibration came from
    std::optional<long long> age_s;  // time since it was made; nullopt when that is not known
    std::string calibrated_at;       // UTC timestamp of its making, or "" (a config's section)
    // The run that made it (POST /v1/calibrate): reference_m, quality and uncertainty; null for a
    // calibration that came with the config.
    nlohmann::json run;
};

// A finished calibration of the station (POST /v1/calibrate): the calibrator's report, and when
// and with which reference the daemon ran it.
struct CalibrationRun {
    CalibrationReport report;
    std::string calibrated_at;  // UTC timestamp
    BoxDimensions reference;    // as the request gave it (any order of length and width)
};

class Station {
public:
    virtual ~Station() = default;

    // Brings the devices up (connects, homes); returns the first device error. Called at start
    // and again before a run when a previous run left the devices in error.
    virtual Status Open() = 0;
    // Returns true when Open() succeeded and no device error happened since.
    virtual bool IsOpen() const = 0;
    // Captures and measures one parcel. Never throws for expected failures: they come back as a
    // result with status no_dim/failed and a reason. Returns soon after ctx.cancel is set.
    virtual JobOutput Measure(const JobContext& ctx) = 0;
    // Captures a session of a reference box of size `reference` (any order of length and
    // width), estimates the station calibration from it and puts it in force for the following
    // measurements. Returns the calibration run, or the device / calibration error. Returns soon
    // after ctx.cancel is set.
    virtual Result<CalibrationRun> Calibrate(const JobContext& ctx,
                                             const BoxDimensions& reference) = 0;
    // Stops the turntable now. Any thread; does not wait for the run to return.
    virtual void RequestStop() = 0;
    // Brings the devices to rest before the process exits (table stopped, connections closed).
    virtual void Shutdown() = 0;
    // Returns the devices' description and health for GET /v1/status (cached, never blocks on
    // a device).
    virtual DeviceHealth Devices() const = 0;
    // Returns the calibration in force for GET /v1/calibration.
    virtual CalibrationInForce Calibration() const = 0;
    // Sends the scale's "zero" or "tare" command (POST /v1/scale/zero|tare) and returns the
    // scale's description; NOT_FOUND for a station without a scale, SCALE_ERROR when it fails.
    virtual Result<std::string> ScaleCommand(const std::string& command) {
        (void)command;
        return Error{ErrorCode::kNotFound, "the station has no scale"};
    }
};

}  // namespace boxd
