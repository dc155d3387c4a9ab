#include "daemon/service/service_loop.h"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>

#include "daemon/service/audit_trail.h"
#include "daemon/service/http_api.h"
#include "daemon/service/measurement_service.h"
#include "daemon/service/measurement_store.h"
#include "daemon/service/mqtt_publisher.h"
#include "daemon/service/service_json.h"
#include "daemon/service/signal_flags.h"
#include "daemon/service/systemd_notifier.h"
#include "drivers/station_config.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/station_calibration_json.h"

namespace boxd {

namespace {

using Clock = std::chrono::steady_clock;

// The loop wakes at least this often, so /v1/health can tell a live loop from a stuck one.
constexpr auto kMaxTick = std::chrono::milliseconds(500);
constexpr auto kStalledAfter = std::chrono::seconds(5);

// A data folder or an address of the config that cannot be used at start-up is a bad config
// (exit 2, SPEC section 4): the operator fixes the config, not the program.
Error BadConfig(const std::string& message) { return Error{ErrorCode::kInvalidConfig, message}; }

// The one-line STATUS= text of a state.
std::string StatusLine(const ServiceSnapshot& s) {
    switch (s.state) {
        case ServiceState::kMeasuring:
            return "measuring " + s.measurement_id + ": " + s.progress.stage + " pose " +
                   std::to_string(s.progress.pose) + "/" + std::to_string(s.progress.poses);
        case ServiceState::kError:
            return "error: " + (s.last_error ? ErrorCodeName(s.last_error->code) +
                                                   std::string(": ") + s.last_error->message
                                             : std::string("devices not ready"));
        default:
            return std::string(ServiceStateName(s.state)) +
                   (s.last_measurement_id.empty() ? "" : ", last " + s.last_measurement_id);
    }
}

class ServiceLoop {
public:
    ServiceLoop(ServeConfig config, std::filesystem::path config_file, ServeOverrides overrides,
                SoftwareIdentity software)
        : config_(std::move(config)),
          config_file_(std::move(config_file)),
          overrides_(std::move(overrides)),
          software_(std::move(software)) {}

    Status Run();

private:
    // Opens the store, the audit trail, the service, MQTT and the API (the daemon's start).
    Status Start();
    // Runs the loop until SIGTERM/SIGINT: ticks, the watchdog, reloads.
    void Serve();
    // Refuses new work, stops the table, lets the run record its abort, stops serving.
    void Stop();
    void Reload();
    void Tick();
    // Opens the audit trail and checks the stored records' chain (logged, and kept for status).
    Status OpenAuditTrail();
    // Records each metrological setting that changed since it was last seen, as coming `via`.
    void ObserveSettings(const std::string& via);
    // The calibration in force, as the audit trail compares it.
    std::string CalibrationText() const;
    std::optional<AuditStatus> Audit() const;
    std::shared_ptr<Station> MakeStation(const ServeConfig& config) {
        return std::make_shared<DeviceStation>(config.station);
    }

    ServeConfig config_;
    std::filesystem::path config_file_;
    ServeOverrides overrides_;
    SoftwareIdentity software_;
    SystemdNotifier notifier_;
    std::unique_ptr<AuditTrail> audit_;
    ChainReport chain_;  // the records' chain as checked at start (read by HTTP threads after)
    std::string chain_checked_at_;
    std::atomic<bool> calibrated_{false};  // a calibration run put a new one in force
    std::unique_ptr<MeasurementStore> store_;
    std::unique_ptr<MeasurementService> service_;
    std::unique_ptr<HttpApi> api_;
    std::unique_ptr<MqttPublisher> mqtt_;  // with an mqtt: section
    std::atomic<long long> last_tick_ms_{0};
    std::string last_status_;
    bool reload_pending_ = false;
    Clock::time_point next_watchdog_;
};

long long NowMs() {
    return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now().time_since_epoch())
        .count();
}

Status ServiceLoop::Run() {
    if (!InstallSignalFlags()) {
        return Error{ErrorCode::kInternal, "cannot install the signal handlers"};
    }
    if (Status s = Start(); !s) return s;
    // The devices come up on their own thread (`starting`): the loop answers signals meanwhile,
    // and a measurement requested before they are up waits for them.
    service_->OpenStationInBackground();
    last_status_ = StatusLine(service_->Snapshot());
    notifier_.Ready(last_status_);
    spdlog::info("boxd serve ready: {}", last_status_);
    if (notifier_.watchdog_interval().count() > 0) {
        spdlog::info("systemd watchdog: pinging every {} ms",
                     notifier_.watchdog_interval().count());
    }

    Serve();
    Stop();
    spdlog::info("stopped");
    return OkStatus();
}

Status ServiceLoop::Start() {
    auto store = MeasurementStore::Open(config_.storage.data_dir, config_.storage.retention);
    if (!store) return BadConfig("storage.data_dir: " + store.error().message);
    store_ = std::move(*store);
    if (Status s = OpenAuditTrail(); !s) return s;

    service_ = std::make_unique<MeasurementService>(*store_, MakeStation(config_),
                                                    config_.storage.keep_sessions);
    service_->set_software(software_);
    service_->set_on_calibrated([this] {
        calibrated_ = true;
        WakeMainLoop();
    });
    service_->set_on_change([] { WakeMainLoop(); });
    ObserveSettings("config file " + config_file_.string() + " at start");
    if (config_.mqtt.enabled) {
        auto mqtt = MqttPublisher::Start(config_.mqtt);
        if (!mqtt) return BadConfig(mqtt.error().message);
        mqtt_ = std::move(*mqtt);
        service_->set_on_finished([this](const MeasurementResult& r) {
            mqtt_->PublishMeasurement(r.id, JsonText(ToJson(r)));
        });
    }
    last_tick_ms_ = NowMs();
    api_ = std::make_unique<HttpApi>(config_.server, *service_, *store_, [this] {
        return NowMs() - last_tick_ms_.load() <
               std::chrono::duration_cast<std::chrono::milliseconds>(kStalledAfter).count();
    });
    if (mqtt_) {
        api_->set_mqtt_stats([this]() -> std::optional<MqttStats> { return mqtt_->Stats(); });
    }
    api_->set_audit(audit_.get(), [this] { return Audit(); });
    if (Status s = api_->Start(); !s) return BadConfig(s.error().message);
    return OkStatus();
}

void ServiceLoop::Serve() {
    next_watchdog_ = Clock::now();
    bool terminate = false;
    while (!terminate) {
        Tick();
        auto timeout = kMaxTick;
        if (notifier_.watchdog_interval().count() > 0) {
            timeout = std::min(timeout, std::chrono::duration_cast<std::chrono::milliseconds>(
                                            next_watchdog_ - Clock::now()));
        }
        pollfd pfd{SignalWakeFd(), POLLIN, 0};
        poll(&pfd, 1, static_cast<int>(std::max<long long>(0, timeout.count())));
        DrainSignalWakeFd();
        if (TakeTerminateRequest()) terminate = true;
        if (TakeReloadRequest()) reload_pending_ = true;
        if (reload_pending_ && !terminate && !service_->Busy()) {
            reload_pending_ = false;
            Reload();
        }
    }
}

void ServiceLoop::Stop() {
    // Shutdown: refuse new work, stop the table at once, let the run record its abort, then
    // bring the devices to rest and stop serving.
    const bool busy = service_->Busy();
    notifier_.Stopping(busy ? "stopping: aborting the running measurement" : "stopping");
    spdlog::info("stopping{}", busy ? ": aborting the running measurement" : "");
    service_->Abort();
    // Before the join: an open still under way (a drive starting or homing) is abandoned, and a
    // run waiting for it is answered, so the stop does not wait for a slow device.
    service_->station()->Shutdown();
    service_->Join();
    if (mqtt_) mqtt_->Stop();  // the aborted run is sent first, then {"state": "offline"}
    api_->Stop();
    api_.reset();
    service_.reset();
    mqtt_.reset();
}

void ServiceLoop::Tick() {
    last_tick_ms_ = NowMs();
    // WATCHDOG=1 comes from this loop only while the API still serves: a stuck loop or a dead
    // listener stops the pings and systemd restarts the daemon.
    if (notifier_.watchdog_interval().count() > 0 && Clock::now() >= next_watchdog_) {
        if (api_->Running()) notifier_.Watchdog();
        next_watchdog_ = Clock::now() + notifier_.watchdog_interval();
    }
    // At run time the calibration changes only through POST /v1/calibrate (a reload observes
    // its own changes).
    if (calibrated_.exchange(false)) ObserveSettings("POST /v1/calibrate");
    const ServiceSnapshot snapshot = service_->Snapshot();
    if (mqtt_) mqtt_->PublishState(JsonText(MqttStateJson(snapshot, config_.mqtt.station_id)));
    const std::string status = StatusLine(snapshot);
    if (status != last_status_) {
        last_status_ = status;
        notifier_.Status(status);
        spdlog::debug("status: {}", status);
    }
}

void ServiceLoop::Reload() {
    spdlog::info("SIGHUP: reloading {}", config_file_.string());
    notifier_.Reloading();
    auto fresh = LoadServeConfig(config_file_, overrides_);
    if (!fresh) {
        spdlog::error("reload failed, keeping the running config: {}", fresh.error().message);
        notifier_.Ready(StatusLine(service_->Snapshot()));
        return;
    }
    if (!(fresh->server == config_.server)) {
        spdlog::warn("reload: server.* changes take effect at the next restart");
        fresh->server = config_.server;
    }
    if (!(fresh->mqtt == config_.mqtt)) {
        spdlog::warn("reload: mqtt.* changes take effect at the next restart");
        fresh->mqtt = config_.mqtt;
    }
    if (fresh->storage.data_dir != config_.storage.data_dir) {
        spdlog::warn("reload: storage.data_dir changes take effect at the next restart");
        fresh->storage.data_dir = config_.storage.data_dir;
    }
    store_->set_retention(fresh->storage.retention);
    if (Status s = service_->ReplaceStation(MakeStation(*fresh), fresh->storage.keep_sessions);
        !s) {
        // A run started since the loop saw the service idle: reload once it has finished.
        spdlog::info("reload: {}; reloading after it", s.error().message);
        reload_pending_ = true;
        notifier_.Ready(StatusLine(service_->Snapshot()));
        return;
    }
    config_ = std::move(*fresh);
    ObserveSettings("config file " + config_file_.string() + ", SIGHUP reload");
    service_->OpenStationInBackground();
    notifier_.Ready(StatusLine(service_->Snapshot()));
    spdlog::info("reload done");
}

Status ServiceLoop::OpenAuditTrail() {
    auto audit = AuditTrail::Open(config_.storage.data_dir);
    if (!audit) return BadConfig("storage.data_dir: " + audit.error().message);
    audit_ = std::move(*audit);
    chain_checked_at_ = UtcTimestampNow();
    auto chain = store_->VerifyChain();
    if (!chain) return BadConfig("storage.data_dir: " + chain.error().message);
    chain_ = *chain;
    if (chain_.intact) {
        spdlog::info(
            "stored records: {} checked against their hash chain, intact{}", chain_.records,
            chain_.unchained
                ? " (" + std::to_string(chain_.unchained) + " from before the chain not checked)"
                : std::string());
    } else {
        spdlog::error("stored records: the hash chain is broken: {} (boxd verify --data-dir {})",
                      chain_.problem, config_.storage.data_dir);
    }
    return OkStatus();
}

std::string ServiceLoop::CalibrationText() const {
    const CalibrationInForce c = service_->station()->Calibration();
    return c.calibration ? JsonText(ToJson(*c.calibration)) : "none";
}

void ServiceLoop::ObserveSettings(const std::string& via) {
    std::vector<std::pair<std::string, std::string>> settings = {
        {"software", JsonText(ToJson(software_))}, {"calibration", CalibrationText()}};
    if (via != "POST /v1/calibrate") {
        auto root = LoadConfigSections(config_file_);
        if (!root) {
            spdlog::error("audit trail: {}", root.error().message);
            return;
        }
        for (const char* section : {"measurement", "scale", "billing"}) {
            settings.emplace_back(section, SectionText((*root)[section]));
        }
    }
    for (const auto& [what, value] : settings) {
        if (auto changed = audit_->Observe(what, value, via); !changed) {
            spdlog::error("audit trail: {}", changed.error().message);
        }
    }
}

std::optional<AuditStatus> ServiceLoop::Audit() const {
    AuditStatus a;
    a.event_counter = audit_->Counter();
    if (auto last = audit_->Events(1); last && !last->empty()) a.last_event = last->front();
    a.software = software_;
    a.chain = chain_;
    a.chain_checked_at = chain_checked_at_;
    // The head as it is now (the check's verdict is the start's).
    if (auto head = store_->ChainHeadHash(); head) a.chain.head = *head;
    return a;
}

}  // namespace

Status RunService(ServeConfig config, const std::filesystem::path& config_file,
                  const ServeOverrides& overrides, const SoftwareIdentity& software) {
    ServiceLoop loop(std::move(config), config_file, overrides, software);
    return loop.Run();
}

}  // namespace boxd
