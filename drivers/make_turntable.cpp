// MakeTurntable: picks the Turntable implementation that `turntable.driver` names.
#include <algorithm>

#include "drivers/modbus_turntable.h"
#include "drivers/sim/sim_turntable_process.h"
#include "drivers/turntable.h"

namespace boxd {

namespace {

// "simulated": `boxd sim-turntable` as a child process (SimTurntableProcess), driven by the
// ordinary ModbusTurntable over loopback — the same code path as a real drive.
class SimulatedTurntable : public Turntable {
public:
    static Result<std::unique_ptr<Turntable>> Start(const TurntableConfig& config,
                                                    const std::atomic<bool>* cancel) {
        SimTurntableLaunch launch;
        launch.cancel = cancel;
        launch.binary = config.simulator_binary;
        launch.port = config.port;
        // The simulated drive's top speed allows any configured speed; the speed register
        // (from turntable.speed_dps) sets the pace.
        launch.args = {"--speed-dps", std::to_string(std::max(90.0, config.speed_dps))};
        auto process = SimTurntableProcess::Start(launch);
        if (!process) return process.error();
        TurntableConfig client = config;
        client.driver = "modbus-tcp";
        client.host = "127.0.0.1";
        client.port = (*process)->port();
        auto driver = ModbusTurntable::Open(client);
        if (!driver) return driver.error();
        std::unique_ptr<SimulatedTurntable> table(new SimulatedTurntable());
        table->process_ = std::move(*process);
        table->driver_ = std::move(*driver);
        return std::unique_ptr<Turntable>(std::move(table));
    }

    ~SimulatedTurntable() override {
        driver_.reset();  // the client lets go of the connection before the server stops
        process_.reset();
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

    std::unique_ptr<SimTurntableProcess> process_;
    std::unique_ptr<ModbusTurntable> driver_;
};

}  // namespace

Result<std::unique_ptr<Turntable>> MakeTurntable(const TurntableConfig& config,
                                                 const std::atomic<bool>* cancel) {
    if (auto st = config.Validate(); !st) return st.error();
    if (config.driver == "simulated") return SimulatedTurntable::Start(config, cancel);
    auto driver = ModbusTurntable::Open(config);
    if (!driver) return driver.error();
    return std::unique_ptr<Turntable>(std::move(*driver));
}

}  // namespace boxd
