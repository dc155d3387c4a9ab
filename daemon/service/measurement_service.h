#pragma once
// MeasurementService: runs one measurement at a time on its own thread, tracks the state
// (idle / measuring / calibrating / error) and the progress, stores every finished measurement
// and lets HTTP handlers wait for one. Thread-safe; HTTP threads and the main loop share it.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "daemon/service/calibration_history.h"
#include "daemon/service/measurement_store.h"
#include "daemon/service/service_metrics.h"
#include "daemon/service/station.h"
#include "pipeline/core/result.h"

namespace boxd {

enum class ServiceState { kStarting, kIdle, kMeasuring, kCalibrating, kError };

// Returns "starting" / "idle" / "measuring" / "calibrating" / "error".
const char* ServiceStateName(ServiceState s);

struct ServiceSnapshot {
    ServiceState state = ServiceState::kIdle;
    std::string measurement_id;  // the running one, or empty
    JobProgress progress;        // of the running one
    std::optional<Error> last_error;
    std::string last_error_at;        // UTC timestamp of last_error
    std::string last_measurement_id;  // the last finished one (restored from the store), or ""
    int finished = 0;                 // measurements finished since start
};

class MeasurementService {
public:
    MeasurementService(MeasurementStore& store, std::shared_ptr<Station> station,
                       bool keep_sessions);
    // Aborts a running measurement and waits for it.
    ~MeasurementService();
    MeasurementService(const MeasurementService&) = delete;
    MeasurementService& operator=(const MeasurementService&) = delete;

    // Brings the station's devices up; on failure the state is `error` with the device error.
    Status OpenStation();
    // Brings the station's devices up on a thread of their own (at start, after a reload, after
    // a device fault), unless that is already under way; the state is `starting` meanwhile. A
    // measurement started meanwhile waits for that open (Station::Open coalesces).
    void OpenStationInBackground();

    // Starts a measurement (of the parcel `parcel_id`, when given: kept with its result) and
    // returns its id, or BUSY while one runs, SHUTTING_DOWN after Abort(), STORAGE_ERROR when no
    // id can be reserved.
    Result<std::string> Start(std::optional<std::string> parcel_id = std::nullopt);
    // Returns the result of measurement `id` once it has finished (it may already have), or
    // TIMEOUT after `timeout`, SHUTTING_DOWN if the run was abandoned.
    Result<MeasurementResult> WaitFor(const std::string& id, std::chrono::milliseconds timeout);

    // Runs a station calibration with a reference box of size `reference` and returns its
    // report once done; BUSY while a measurement or calibration runs, TIMEOUT after `timeout`
    // (the calibration goes on), SHUTTING_DOWN after Abort(), or the station's error.
    Result<CalibrationRun> Calibrate(const BoxDimensions& reference,
                                     std::chrono::milliseconds timeout);

    // Sends the station's scale `command` ("zero" or "tare") and returns its description; BUSY
    // while a measurement or calibration runs, or the station's error.
    Result<std::string> ScaleCommand(const std::string& command);

    // Returns up to `limit` finished calibrations, newest first, as CalibrationHistory::List
    // reads them from storage, or STORAGE_ERROR when the history is not available.
    Result<std::vector<nlohmann::json>> ListCalibrations(int limit);

    // Stops the running measurement (the table is stopped at once) and refuses new ones.
    void Abort();
    // Waits until no measurement runs and no background open is under way.
    void Join();

    bool Busy() const;
    ServiceSnapshot Snapshot() const;
    // The counters of GET /metrics: every finished measurement and every device fault.
    const ServiceMetrics& metrics() const { return metrics_; }
    std::shared_ptr<Station> station() const;

    // Puts a new station (and the keep-sessions setting) in force; BUSY while a run uses the
    // old one. Runs are refused (BUSY) while the old station is shut down (an open of it under
    // way is abandoned) and replaced. The new station's devices are opened by the caller
    // (OpenStation...()).
    Status ReplaceStation(std::shared_ptr<Station> station, bool keep_sessions);

    // The program's identification, put in every finished measurement. Set before the first
    // measurement starts.
    void set_software(SoftwareIdentity software) { software_ = std::move(software); }
    // Called (from the calibration's thread) when a calibration has put a new one in force. Set
    // before the first calibration starts.
    void set_on_calibrated(std::function<void()> on_calibrated) {
        on_calibrated_ = std::move(on_calibrated);
    }
    // Called (from any thread) whenever the state or the progress changes.
    void set_on_change(std::function<void()> on_change);
    // Called (from the measurement's thread) with every finished measurement, once it is
    // stored (or failed to be). Set before the first measurement starts.
    void set_on_finished(std::function<void(const MeasurementResult&)> on_finished) {
        on_finished_ = std::move(on_finished);
    }

private:
    // Opens `station`'s devices; records the outcome if it is still the station in force.
    Status OpenStation(const std::shared_ptr<Station>& station);
    // Claims the background open (under mutex_); false when one is under way or none may start.
    bool ClaimOpenerLocked();
    // Starts the claimed background open of the station in force.
    void LaunchOpener();
    void Run(std::string id, std::filesystem::path scratch, std::shared_ptr<Station> station,
             std::optional<std::string> parcel_id);
    JobOutput RunStation(Station& station, const JobContext& ctx);
    struct CalibrationJob;
    void RunCalibration(std::shared_ptr<CalibrationJob> job, std::shared_ptr<Station> station);
    // Adds the finished calibration (report or refusal) to the history.
    void RecordCalibration(const BoxDimensions& reference, const Result<CalibrationRun>& result);
    // Claims the worker for a new run; returns the previous (finished) worker thread to join.
    Result<std::thread> Claim(bool calibrating);
    // Records the running job's progress (from its thread) and notifies.
    void SetProgress(const JobProgress& progress);
    void Notify();

    MeasurementStore& store_;
    mutable std::mutex mutex_;
    std::condition_variable finished_cv_;
    std::shared_ptr<Station> station_;
    bool keep_sessions_ = false;
    bool station_opened_ = false;  // OpenStation() has run on the station in force
    bool opening_ = false;         // OpenStationInBackground() is under way
    bool replacing_ = false;       // ReplaceStation() is under way: no run, no open starts
    std::thread opener_;           // its thread
    bool running_ = false;
    bool calibrating_ = false;
    bool shutting_down_ = false;
    std::atomic<bool> cancel_{false};
    std::string current_id_;
    JobProgress progress_;
    std::optional<Error> last_error_;
    std::string last_error_at_;
    std::string last_id_;
    // The latest finished results, oldest first (the last one is kept in memory too, in case
    // storing it failed); WaitFor answers from here.
    std::deque<MeasurementResult> recent_;
    int finished_ = 0;
    std::thread worker_;
    std::function<void()> on_change_;
    std::function<void(const MeasurementResult&)> on_finished_;
    std::optional<SoftwareIdentity> software_;
    std::function<void()> on_calibrated_;
    std::unique_ptr<CalibrationHistory> history_;
    ServiceMetrics metrics_;  // null when it could not be opened
};

}  // namespace boxd
