// MakeTurntable: picks the Turntable implementation that `turntable.driver` names.
#include <spdlog/spdlog.h>

#include <atomic>
#include <thread>

#include "drivers/modbus_turntable.h"
#include "drivers/turntable.h"
#include "drivers/turntable_simulator.h"

namespace boxd {

namespace {

// "simulated": a TurntableSimulator serving Modbus TCP on a thread of this process, driven by
// the ordinary ModbusTurntable over loopback — the same code path as a real drive.
class SimulatedTurntable : public Turntable {
public:
    static Result<std::unique_ptr<Turntable>> Start(const TurntableConfig& config) {
        std::unique_ptr<SimulatedTurntable> table(new SimulatedTurntable());
        TurntableSimulatorConfig sim;
        // The simulated drive is fast enough for any configured speed; the speed register
        // (from turntable.speed_dps) sets the pace.
        sim.max_speed_dps = std::max(sim.max_speed_dps, config.speed_dps);
        table->simulator_ = std::make_unique<TurntableSimulator>(sim);
        if (auto st = table->simulator_->ListenTcp(config.host, config.port); !st) {
            return Error{kTurntableErrorCode, "simulated turntable: " + st.error().message};
        }
        table->thread_ = std::thread([t = table.get()] {
            if (auto st = t->simulator_->Serve(t->stop_server_); !st) {
                spdlog::error("{}", st.error().message);
            }
        });
        TurntableConfig client = config;
        client.driver = "modbus-tcp";
        client.port = table->simulator_->port();
        auto driver = ModbusTurntable::Open(client);
        if (!driver) return driver.error();
        table->driver_ = std::move(*driver);
        return std::unique_ptr<Turntable>(std::move(table));
    }

    ~SimulatedTurntable() override {
        driver_.reset();
        stop_server_.store(true);
        if (thread_.joinable()) thread_.join();
    }

    Status Home() override { return driver_->Home(); }
    Status MoveTo(double angle_deg) override { return driver_->MoveTo(angle_deg); }
    Result<double> CurrentAngleDeg() override { return driver_->CurrentAngleDeg(); }
    Status Stop() override { return driver_->Stop(); }
    Result<TurntableState> State() override { return driver_->State(); }
    void RequestStop() override { driver_->RequestStop(); }
    void ClearStopRequest() override { driver_->ClearStopRequest(); }
    std::string Describe() const override { return "simulated, " + driver_->Describe(); }

private:
    SimulatedTurntable() = default;

    std::unique_ptr<TurntableSimulator> simulator_;
    std::atomic<bool> stop_server_{false};
    std::thread thread_;
    std::unique_ptr<ModbusTurntable> driver_;
};

}  // namespace

Result<std::unique_ptr<Turntable>> MakeTurntable(const TurntableConfig& config) {
    if (auto st = config.Validate(); !st) return st.error();
    if (config.driver == "simulated") return SimulatedTurntable::Start(config);
    auto driver = ModbusTurntable::Open(config);
    if (!driver) return driver.error();
    return std::unique_ptr<Turntable>(std::move(*driver));
}

}  // namespace boxd
