#pragma once
// ScriptedStation: a station without devices whose measurement ends at once with a fixed box (or
// a turntable fault on demand), or is held mid-capture until the test releases it. Used by the
// HTTP API's tests and its fuzzer to reach every service state on demand.

#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>

#include "daemon/service/billing.h"
#include "daemon/service/station.h"

namespace boxd {

// A station whose measurement can be held mid-capture until the test releases it.
class ScriptedStation : public Station {
public:
    std::atomic<bool> hold{false};
    std::atomic<bool> in_capture{false};
    std::atomic<int> stop_requests{0};
    std::atomic<bool> fail_next{false};
    std::atomic<bool> refuse_next{false};  // the next measurement is no_dim MULTIPLE_OBJECTS
    std::atomic<bool> fail_open{false};    // opens fail (a drive that does not answer)

    Status Open() override {
        if (fail_open) return Error{ErrorCode::kTurntableError, "sim: no answer"};
        open_ = true;
        return OkStatus();
    }
    bool IsOpen() const override { return open_; }
    JobOutput Measure(const JobContext& ctx) override {
        JobOutput out;
        ctx.progress(JobProgress{"capture", 1, 4});
        in_capture = true;
        while (hold && !ctx.cancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
        in_capture = false;
        if (ctx.cancelled()) {
            out.result.reason = MeasurementReason{ErrorCode::kCancelled, "capture cancelled"};
            return out;
        }
        if (fail_next.exchange(false)) {
            open_ = false;
            out.result.reason = MeasurementReason{ErrorCode::kTurntableError, "sim: stall"};
            return out;
        }
        out.result.timing_ms["capture"] = 12.0;
        out.result.timing_ms["processing"] = 80.0;
        if (refuse_next.exchange(false)) {
            out.result.status = MeasurementStatus::kNoDim;
            out.result.reason = MeasurementReason{ErrorCode::kMultipleObjects, "two objects"};
            return out;
        }
        out.result.status = MeasurementStatus::kOk;
        out.result.dimensions = MeasuredDimensions{0.4, 0.3, 0.2, 0.024, "footprint"};
        out.result.quality.poses = 4;
        // A station that bills, weighed at 2.5 kg (the block's schema is checked on it).
        out.result.billing = Bill({0.4, 0.3, 0.2}, {0.001, 0.001, 0.001}, 2.5, BillingConfig{});
        out.result.weight = Weighing{2.5, "", "kg", 0.005, 520.0, 11, "scripted indicator"};
        const auto ply = ctx.scratch_dir / "cloud.ply";
        std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
        out.files.cloud_ply = ply;
        return out;
    }
    Result<CalibrationRun> Calibrate(const JobContext& ctx,
                                     const BoxDimensions& reference) override {
        ctx.progress(JobProgress{"capture", 2, 4});
        in_capture = true;
        while (hold && !ctx.cancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
        in_capture = false;
        if (ctx.cancelled()) return Error{ErrorCode::kCancelled, "capture cancelled"};
        if (reference.height_m > 1.0)
            return Error{ErrorCode::kWrongReference, "measured 0.2 m high"};
        return CalibrationRun{CalibrationReport{}, "2026-01-01T00:00:00.000Z", reference};
    }
    void RequestStop() override { ++stop_requests; }
    void Shutdown() override { open_ = false; }
    DeviceHealth Devices() const override {
        DeviceHealth devices;
        devices.turntable.ok = open_.load();
        return devices;
    }
    CalibrationInForce Calibration() const override {
        CalibrationInForce c;
        c.calibration = StationCalibration{};
        c.source = "calibration.json";
        c.age_s = 42;
        c.calibrated_at = "2026-01-01T00:00:00.000Z";
        return c;
    }

private:
    std::atomic<bool> open_{false};
};

}  // namespace boxd
