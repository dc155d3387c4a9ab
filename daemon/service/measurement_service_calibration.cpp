// MeasurementService's calibration runs (POST /v1/calibrate): one at a time on the worker, like
// measurements, each finished one (report or refusal) kept in the calibration history; and the
// scale's zero and tare between runs.
#include <spdlog/spdlog.h>

#include <exception>

#include "daemon/service/measurement_service.h"

namespace boxd {

using nlohmann::json;

Result<std::vector<json>> MeasurementService::ListCalibrations(int limit) {
    if (!history_)
        return Error{ErrorCode::kStorageError, "the calibration history is not available"};
    return history_->List(limit);
}

Result<std::string> MeasurementService::ScaleCommand(const std::string& command) {
    if (Busy()) return Error{ErrorCode::kBusy, "a measurement or calibration is running"};
    return station()->ScaleCommand(command);
}

struct MeasurementService::CalibrationJob {
    BoxDimensions reference;
    bool done = false;  // guarded by mutex_
    Result<CalibrationRun> result = Error{ErrorCode::kInternal, "not run"};
};

Result<CalibrationRun> MeasurementService::Calibrate(const BoxDimensions& reference,
                                                     std::chrono::milliseconds timeout) {
    Result<std::thread> previous = Claim(true);
    if (!previous) return previous.error();
    if (previous->joinable()) previous->join();
    auto job = std::make_shared<CalibrationJob>();
    job->reference = reference;
    {
        std::lock_guard lock(mutex_);
        worker_ = std::thread(&MeasurementService::RunCalibration, this, job, station_);
    }
    spdlog::info("calibration started, reference {:.4f} x {:.4f} x {:.4f} m", reference.length_m,
                 reference.width_m, reference.height_m);
    Notify();
    std::unique_lock lock(mutex_);
    if (!finished_cv_.wait_for(lock, timeout, [&] { return job->done; })) {
        return Error{ErrorCode::kTimeout, "the calibration is still running"};
    }
    return job->result;
}

void MeasurementService::RecordCalibration(const BoxDimensions& reference,
                                           const Result<CalibrationRun>& result) {
    if (!history_) return;
    CalibrationRecord record;
    record.finished_at = UtcTimestampNow();
    record.reference = reference;
    if (result) {
        record.report = result->report;
    } else {
        record.error = result.error();
    }
    if (Status s = history_->Record(record); !s) {
        spdlog::error("calibration history: {}", s.error().message);
    }
}

void MeasurementService::RunCalibration(std::shared_ptr<CalibrationJob> job,
                                        std::shared_ptr<Station> station) {
    JobContext ctx;
    ctx.id = "calibration";
    ctx.cancel = &cancel_;
    ctx.progress = [this](const JobProgress& p) { SetProgress(p); };
    Result<CalibrationRun> result = Error{ErrorCode::kInternal, "not run"};
    try {
        Status opened = station->IsOpen() ? OkStatus() : station->Open();
        result = opened ? station->Calibrate(ctx, job->reference)
                        : Result<CalibrationRun>(opened.error());
    } catch (const std::exception& e) {
        spdlog::critical("calibration: internal failure: {}", e.what());
        station->RequestStop();
        result = Error{ErrorCode::kInternal, e.what()};
    }
    if (!result && cancel_) {
        result = Error{ErrorCode::kAborted, "calibration aborted: the daemon is stopping"};
    }
    if (result) {
        spdlog::info("calibration done: the new calibration is in force");
        if (on_calibrated_) on_calibrated_();
    } else {
        spdlog::error("calibration failed: {}: {}", ErrorCodeName(result.error().code),
                      result.error().message);
    }
    RecordCalibration(job->reference, result);
    if (!result) metrics_.RecordFault(result.error().code);
    bool reopen = false;
    {
        std::lock_guard lock(mutex_);
        running_ = false;
        calibrating_ = false;
        progress_ = JobProgress{};
        if (!result) {
            last_error_ = result.error();
            last_error_at_ = UtcTimestampNow();
        }
        job->result = std::move(result);
        job->done = true;
        reopen = !station->IsOpen() && ClaimOpenerLocked();  // as after a measurement
    }
    finished_cv_.notify_all();
    Notify();
    if (reopen) LaunchOpener();
}

}  // namespace boxd
