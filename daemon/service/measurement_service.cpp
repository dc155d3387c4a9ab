#include "daemon/service/measurement_service.h"

#include <malloc.h>
#include <spdlog/spdlog.h>

#include <exception>

#include "daemon/service/measurement_log.h"

namespace boxd {

using nlohmann::json;

namespace {

// WaitFor answers from the results kept in memory: a waiter wakes long before this many more
// measurements can finish.
constexpr std::size_t kRecentResults = 8;

MeasurementResult FailedResult(const Error& error) {
    MeasurementResult r;
    r.status = MeasurementStatus::kFailed;
    r.reason = MeasurementReason{error.code, error.message};
    return r;
}

}  // namespace

const char* ServiceStateName(ServiceState s) {
    switch (s) {
        case ServiceState::kStarting:
            return "starting";
        case ServiceState::kIdle:
            return "idle";
        case ServiceState::kMeasuring:
            return "measuring";
        case ServiceState::kCalibrating:
            return "calibrating";
        case ServiceState::kError:
            return "error";
    }
    return "error";
}

MeasurementService::MeasurementService(MeasurementStore& store, std::shared_ptr<Station> station,
                                       bool keep_sessions)
    : store_(store), station_(std::move(station)), keep_sessions_(keep_sessions) {
    auto history = CalibrationHistory::Open(store_.data_dir());
    if (history) {
        history_ = std::move(*history);
    } else {
        spdlog::warn("calibration history unavailable: {}", history.error().message);
    }
    // The last finished measurement survives a restart in the store: /v1/status and the retained
    // MQTT state name it from the start, as GET /v1/measurements/last answers it.
    auto last = store_.Last();
    if (last && *last) {
        last_id_ = (*last)->value("id", "");
    } else if (!last) {
        spdlog::warn("the last measurement cannot be read: {}", last.error().message);
    }
}

MeasurementService::~MeasurementService() {
    Abort();
    Join();
}

void MeasurementService::set_on_change(std::function<void()> on_change) {
    std::lock_guard lock(mutex_);
    on_change_ = std::move(on_change);
}

void MeasurementService::SetProgress(const JobProgress& progress) {
    {
        std::lock_guard lock(mutex_);
        progress_ = progress;
    }
    Notify();
}

void MeasurementService::Notify() {
    std::function<void()> f;
    {
        std::lock_guard lock(mutex_);
        f = on_change_;
    }
    if (f) f();
}

Status MeasurementService::OpenStation() { return OpenStation(station()); }

Status MeasurementService::OpenStation(const std::shared_ptr<Station>& station) {
    Status s = station->Open();
    {
        std::lock_guard lock(mutex_);
        if (station != station_) return s;  // replaced meanwhile: its outcome is not the state
        station_opened_ = true;
        if (!s && s.error().code != ErrorCode::kShuttingDown) {
            last_error_ = s.error();
            last_error_at_ = UtcTimestampNow();
        }
    }
    if (!s && s.error().code != ErrorCode::kShuttingDown) metrics_.RecordFault(s.error().code);
    Notify();
    return s;
}

void MeasurementService::OpenStationInBackground() {
    bool claimed = false;
    {
        std::lock_guard lock(mutex_);
        claimed = ClaimOpenerLocked();
    }
    if (claimed) LaunchOpener();
}

bool MeasurementService::ClaimOpenerLocked() {
    if (opening_ || shutting_down_ || replacing_) return false;
    opening_ = true;
    return true;
}

void MeasurementService::LaunchOpener() {
    std::thread previous;
    {
        std::lock_guard lock(mutex_);
        previous = std::move(opener_);  // a finished opener: only its thread is left
        opener_ = std::thread([this, station = station_] {
            if (Status s = OpenStation(station); !s) {
                spdlog::error("the station is not ready ({}); measurements will retry the devices",
                              s.error().message);
            }
            {
                std::lock_guard done(mutex_);
                opening_ = false;
            }
            finished_cv_.notify_all();
            Notify();
        });
    }
    if (previous.joinable()) previous.join();
    Notify();
}

std::shared_ptr<Station> MeasurementService::station() const {
    std::lock_guard lock(mutex_);
    return station_;
}

Status MeasurementService::ReplaceStation(std::shared_ptr<Station> station, bool keep_sessions) {
    std::shared_ptr<Station> old;
    {
        std::lock_guard lock(mutex_);
        if (running_) return Error{ErrorCode::kBusy, "a measurement is running"};
        replacing_ = true;  // Claim() answers BUSY from here on
        old = station_;
    }
    // The old station lets go of its devices (an open of them under way is abandoned) before the
    // new one opens them.
    old->Shutdown();
    std::thread opener;
    {
        std::lock_guard lock(mutex_);
        opener = std::move(opener_);
    }
    if (opener.joinable()) opener.join();
    {
        std::lock_guard lock(mutex_);
        station_ = std::move(station);
        keep_sessions_ = keep_sessions;
        station_opened_ = false;
        opening_ = false;
        replacing_ = false;
    }
    Notify();
    return OkStatus();
}

Result<std::thread> MeasurementService::Claim(bool calibrating) {
    std::lock_guard lock(mutex_);
    if (shutting_down_) return Error{ErrorCode::kShuttingDown, "the daemon is stopping"};
    if (replacing_) return Error{ErrorCode::kBusy, "the station is being reloaded"};
    if (running_) {
        return Error{ErrorCode::kBusy, calibrating_ ? std::string("a calibration is running")
                                                    : "measurement " + current_id_ + " is running"};
    }
    running_ = true;
    calibrating_ = calibrating;
    cancel_ = false;
    current_id_.clear();
    progress_ = JobProgress{"starting", 0, 0};
    return std::move(worker_);
}

Result<std::string> MeasurementService::Start(std::optional<std::string> parcel_id) {
    Result<std::thread> previous = Claim(false);
    if (!previous) return previous.error();
    if (previous->joinable()) previous->join();  // it has finished; only the thread is left

    auto fail = [this](const Error& e) -> Result<std::string> {
        {
            std::lock_guard lock(mutex_);
            running_ = false;
            last_error_ = e;
            last_error_at_ = UtcTimestampNow();
        }
        finished_cv_.notify_all();
        Notify();
        return e;
    };
    Result<std::string> id = store_.ReserveId();
    if (!id) return fail(id.error());
    Result<std::filesystem::path> scratch = store_.MakeScratchDir(*id);
    if (!scratch) return fail(scratch.error());
    {
        std::lock_guard lock(mutex_);
        current_id_ = *id;
        worker_ = std::thread(&MeasurementService::Run, this, *id, *scratch, station_,
                              std::move(parcel_id));
    }
    spdlog::info("measurement {} started", *id);
    Notify();
    return *id;
}

JobOutput MeasurementService::RunStation(Station& station, const JobContext& ctx) {
    try {
        if (!station.IsOpen()) {
            spdlog::info("opening the station's devices");
            if (Status s = station.Open(); !s) return JobOutput{FailedResult(s.error()), {}};
        }
        return station.Measure(ctx);
    } catch (const std::exception& e) {
        // Stations report expected failures as results; anything thrown is a defect, and it
        // must not take the service loop down with it.
        spdlog::critical("measurement {}: internal failure: {}", ctx.id, e.what());
        station.RequestStop();
        return JobOutput{FailedResult(Error{ErrorCode::kInternal, e.what()}), {}};
    }
}

void MeasurementService::Run(std::string id, std::filesystem::path scratch,
                             std::shared_ptr<Station> station,
                             std::optional<std::string> parcel_id) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string started_at = UtcTimestampNow();
    JobContext ctx;
    ctx.id = id;
    ctx.scratch_dir = scratch;
    ctx.cancel = &cancel_;
    {
        std::lock_guard lock(mutex_);
        ctx.keep_session = keep_sessions_;
    }
    ctx.progress = [this](const JobProgress& p) { SetProgress(p); };

    JobOutput out = RunStation(*station, ctx);
    MeasurementResult& r = out.result;
    r.id = id;
    r.parcel_id = std::move(parcel_id);
    r.started_at = started_at;
    r.finished_at = UtcTimestampNow();
    r.software = software_;
    r.timing_ms["total"] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (cancel_ && r.status != MeasurementStatus::kOk) {
        const std::string why = r.reason ? " (" + std::string(ErrorCodeName(r.reason->code)) +
                                               ": " + r.reason->message + ")"
                                         : std::string();
        r.status = MeasurementStatus::kFailed;
        r.dimensions.reset();
        r.reason = MeasurementReason{ErrorCode::kAborted,
                                     "measurement aborted: the daemon is stopping" + why};
    }
    const Status saved = store_.Save(r, out.files);
    store_.RemoveScratchDir(id);
    if (!saved) {
        // A result that is not stored is not reported as one: its dimensions cannot be fetched
        // again, so a client must not bill by them. The service keeps working; the next
        // measurement is stored again once the disk has room.
        spdlog::error("measurement {} not stored: {}", id, saved.error().message);
        r.status = MeasurementStatus::kFailed;
        r.dimensions.reset();
        r.uncertainty_m.reset();
        r.reason = MeasurementReason{ErrorCode::kStorageError,
                                     "the result could not be stored: " + saved.error().message};
    }
    LogMeasurement(r);
    metrics_.RecordMeasurement(r);
    if (on_finished_) on_finished_(r);
    bool reopen = false;
    {
        std::lock_guard lock(mutex_);
        running_ = false;
        current_id_.clear();
        progress_ = JobProgress{};
        last_id_ = id;
        recent_.push_back(r);
        if (recent_.size() > kRecentResults) recent_.pop_front();
        ++finished_;
        if (!saved) {
            last_error_ = saved.error();
            last_error_at_ = r.finished_at;
        } else if (r.status == MeasurementStatus::kFailed && r.reason) {
            last_error_ = Error{r.reason->code, r.reason->message};
            last_error_at_ = r.finished_at;
        }
        // A device fault closed the devices: they are opened again now, not when the next parcel
        // is already waiting (which then waits for this open). Claimed with the run's end, so
        // the state goes from measuring to starting without a moment of error.
        reopen = !station->IsOpen() && ClaimOpenerLocked();
    }
    finished_cv_.notify_all();
    Notify();
    if (reopen) LaunchOpener();
    // A measurement frees a few hundred megabytes of clouds: hand them back to the system now
    // rather than keep them for the next one (glibc keeps freed memory in its arenas).
    malloc_trim(0);
}

Result<MeasurementResult> MeasurementService::WaitFor(const std::string& id,
                                                      std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    const bool done =
        finished_cv_.wait_for(lock, timeout, [&] { return !(running_ && current_id_ == id); });
    if (!done) return Error{ErrorCode::kTimeout, "measurement " + id + " is still running"};
    for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
        if (it->id == id) return *it;
    }
    return Error{ErrorCode::kNotFound, "no measurement " + id};
}

void MeasurementService::Abort() {
    std::shared_ptr<Station> station;
    {
        std::lock_guard lock(mutex_);
        shutting_down_ = true;
        if (!running_) return;
        station = station_;
    }
    cancel_ = true;
    station->RequestStop();
}

void MeasurementService::Join() {
    std::thread worker, opener;
    {
        // A run that was claimed but whose thread is not made yet (Start() reserving its id),
        // and an open claimed but not launched, are waited for too: their threads exist once
        // the flags are down again.
        std::unique_lock lock(mutex_);
        finished_cv_.wait(lock, [this] { return !running_ && !opening_; });
        worker = std::move(worker_);
        opener = std::move(opener_);
    }
    if (worker.joinable()) worker.join();
    if (opener.joinable()) opener.join();
}

bool MeasurementService::Busy() const {
    std::lock_guard lock(mutex_);
    return running_;
}

ServiceSnapshot MeasurementService::Snapshot() const {
    std::lock_guard lock(mutex_);
    ServiceSnapshot s;
    // The station's own flag is the truth of its devices (an atomic: never waits on them).
    s.state = running_   ? (calibrating_ ? ServiceState::kCalibrating : ServiceState::kMeasuring)
              : opening_ ? ServiceState::kStarting  // the devices are coming up
              : station_->IsOpen() ? ServiceState::kIdle
              : station_opened_    ? ServiceState::kError
                                   : ServiceState::kStarting;
    s.measurement_id = current_id_;
    s.progress = progress_;
    s.last_error = last_error_;
    s.last_error_at = last_error_at_;
    s.last_measurement_id = last_id_;
    s.finished = finished_;
    return s;
}

}  // namespace boxd
