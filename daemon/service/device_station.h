#pragma once
// DeviceStation: the Station of a configured turntable + depth camera (real or simulated) and the
// measurement pipeline. A measurement captures a session pose by pose (progress "pose k of N");
// each pose's share of the recipe (its first stage, its view and its alignments: PosePreparer)
// runs while the table moves on, and the rest (MeasureStreamed), which needs every pose, after
// the last one.

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include "daemon/service/pose_preparer.h"
#include "daemon/service/station.h"
#include "drivers/driver_registry.h"
#include "drivers/station_config.h"
#include "pipeline/measure_config.h"

namespace boxd {

struct DeviceStationConfig {
    StationConfig station;
    MeasureConfig measure;
    BoxMethod method = BoxMethod::kFootprint;
    // The config file the calibration came from: its modification time dates the calibration.
    std::filesystem::path config_file;
    // Where POST /v1/calibrate keeps the calibration it estimated (data_dir/calibration.json).
    // At start the newer of this file and the config's `calibration:` section is in force.
    std::filesystem::path calibration_file;
};

class DeviceStation : public Station {
public:
    explicit DeviceStation(DeviceStationConfig config);
    ~DeviceStation() override;

    Status Open() override;
    bool IsOpen() const override { return open_.load(); }
    JobOutput Measure(const JobContext& ctx) override;
    Result<CalibrationRun> Calibrate(const JobContext& ctx,
                                     const BoxDimensions& reference) override;
    void RequestStop() override;
    void Shutdown() override;
    DeviceHealth Devices() const override;
    CalibrationInForce Calibration() const override;

private:
    // Records a device error: the devices are closed and reopened before the next run.
    void MarkDeviceError(const Error& error);
    void CloseDevices();
    // Captures one session with the open devices; progress is reported as "capture".
    // Captures a session; with a `preparer`, each pose is handed to it as soon as it is grabbed.
    Result<Session> Capture(const JobContext& ctx, double& capture_ms,
                            std::unique_ptr<PosePreparer>* preparer = nullptr);
    // Puts the calibration stored in calibration_file in force when it is newer than the
    // config file's.
    void LoadStoredCalibration();

    DeviceStationConfig config_;
    // Guards devices_ against RequestStop() from another thread while Open() replaces them.
    mutable std::mutex devices_mutex_;
    std::unique_ptr<StationDevices> devices_;
    std::atomic<bool> open_{false};
    std::optional<Error> device_error_;         // guarded by devices_mutex_
    std::string turntable_description_;         // guarded by devices_mutex_
    std::string camera_description_;            // guarded by devices_mutex_
    std::filesystem::path calibration_source_;  // the file the calibration in force came from
    // When the last pose of the capture in progress was grabbed (the job thread's).
    std::chrono::steady_clock::time_point last_frame_at_;
};

}  // namespace boxd
