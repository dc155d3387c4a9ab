#pragma once
// DeviceStation: the Station of a configured turntable + depth camera (real or simulated) and the
// measurement pipeline. A measurement captures a session pose by pose (progress "pose k of N");
// each pose's share of the recipe (its first stage, its view and its alignments: PosePreparer)
// runs while the table moves on, and the rest (MeasureStreamed), which needs every pose, after
// the last one.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include "daemon/service/billing.h"
#include "daemon/service/pose_preparer.h"
#include "daemon/service/station.h"
#include "drivers/driver_registry.h"
#include "drivers/station_config.h"
#include "pipeline/measure_config.h"

namespace boxd {

struct DeviceStationConfig {
    StationConfig station;
    MeasureConfig measure;
    std::optional<BillingConfig> billing;  // the `billing:` section, when the station bills
    BoxMethod method = BoxMethod::kFootprint;
    // The config file the calibration came from: its modification time dates the calibration.
    std::filesystem::path config_file;
    // Where POST /v1/calibrate keeps the calibration it estimated (data_dir/calibration.json).
    // At start the newer of this file and the config's `calibration:` section is in force.
    std::filesystem::path calibration_file;
};

// The one owner of the station's devices. Every open, re-open, capture and close runs under one
// lifecycle lock, so no two threads open, replace or close the devices at once, and a capture
// keeps them (shared) until it returns. Opens coalesce: a caller that arrives while another
// thread opens waits for that open and takes its answer instead of opening again. Shutdown()
// abandons an open in progress (a drive still starting, homing) and refuses later ones.
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
    Result<std::string> ScaleCommand(const std::string& command) override;

private:
    // Opens the devices and homes the table; the caller holds lifecycle_mutex_.
    Status OpenLocked();
    // Returns the devices in use (null when closed), taken under devices_mutex_.
    std::shared_ptr<StationDevices> OpenDevices() const;
    // Records a device error: the devices are closed and reopened before the next run.
    void MarkDeviceError(const Error& error);
    // Stops the table and closes the camera; the caller holds lifecycle_mutex_.
    void CloseLocked();
    // Captures one session with the open devices; progress is reported as "capture".
    // Captures a session; with a `preparer`, each pose is handed to it as soon as it is grabbed.
    Result<Session> Capture(const JobContext& ctx, double& capture_ms,
                            std::unique_ptr<PosePreparer>* preparer = nullptr);
    // Weighs the parcel with the station's scale once it is stable (progress "weighing"):
    // nullopt without a scale, SCALE_ERROR when it cannot.
    Result<std::optional<Weighing>> Weigh(const JobContext& ctx);
    // Puts the calibration stored in calibration_file in force when it is newer than the
    // config file's.
    void LoadStoredCalibration();

    // Held for the whole of an open, a close or a capture: the devices' one lifecycle. Taken
    // before devices_mutex_, never after it.
    std::mutex lifecycle_mutex_;
    // Guards the fields below for the quick readers (RequestStop, Devices, Calibration), which
    // never wait for a device.
    mutable std::mutex devices_mutex_;
    DeviceStationConfig config_;  // its calibration is written under both locks
    std::shared_ptr<StationDevices> devices_;
    std::shared_ptr<StationDevices> opening_;  // being homed by Open(), for RequestStop()
    std::atomic<bool> open_{false};
    std::atomic<bool> stopping_{false};  // Shutdown(): opens are abandoned and refused
    std::uint64_t opens_finished_ = 0;   // opens that have returned, and the last one's answer
    Status last_open_ = OkStatus();
    std::optional<Error> device_error_;
    std::string turntable_description_;
    std::string camera_description_;
    std::string scale_description_;
    std::optional<Error> scale_error_;          // the last weighing's, until one succeeds
    std::filesystem::path calibration_source_;  // the file the calibration in force came from
    // When the calibration in force was made and the run that made it (POST /v1/calibrate's:
    // reference, quality, uncertainty); "" and null for a config's calibration section.
    std::string calibrated_at_;
    nlohmann::json calibration_run_;
    // When the last pose of the capture in progress was grabbed (the job thread's).
    std::chrono::steady_clock::time_point last_frame_at_;
};

}  // namespace boxd
