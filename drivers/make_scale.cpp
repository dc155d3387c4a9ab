// MakeScale: picks the Scale implementation that `scale.driver` names.
#include <spdlog/spdlog.h>

#include <thread>

#include "drivers/modbus_scale.h"
#include "drivers/scale.h"
#include "drivers/sim/scale_simulator.h"

namespace boxd {

namespace {

// "simulated": the simulated indicator served over Modbus TCP on loopback by a thread of this
// process, read by the ordinary ModbusScale — the same code path as a real indicator.
class SimulatedScale : public Scale {
public:
    static Result<std::unique_ptr<Scale>> Start(const ScaleConfig& config) {
        std::unique_ptr<SimulatedScale> scale(new SimulatedScale(config));
        if (auto st = scale->simulator_.ListenTcp("127.0.0.1", 0); !st) {
            return Error{ErrorCode::kScaleError, st.error().message};
        }
        scale->server_ = std::thread([s = scale.get()] {
            if (Status served = s->simulator_.Serve(s->stop_); !served) {
                spdlog::error("sim-scale: {}", served.error().message);
            }
        });
        ScaleConfig client = config;
        client.driver = "modbus-tcp";
        client.host = "127.0.0.1";
        client.port = scale->simulator_.port();
        client.registers = ScaleProfile{};  // the map the simulated indicator serves
        auto driver = ModbusScale::Open(client);
        if (!driver) return driver.error();
        scale->driver_ = std::move(*driver);
        return std::unique_ptr<Scale>(std::move(scale));
    }

    ~SimulatedScale() override {
        driver_.reset();  // the client lets go of the connection before the server stops
        stop_ = true;
        if (server_.joinable()) server_.join();
    }

    Result<ScaleReading> Read() override { return driver_->Read(); }
    Status Zero() override { return driver_->Zero(); }
    Status Tare() override { return driver_->Tare(); }
    std::string Describe() const override { return "simulated, " + driver_->Describe(); }

private:
    explicit SimulatedScale(const ScaleConfig& config) : simulator_(config) {}

    ScaleSimulator simulator_;
    std::atomic<bool> stop_{false};
    std::thread server_;
    std::unique_ptr<ModbusScale> driver_;
};

}  // namespace

Result<std::unique_ptr<Scale>> MakeScale(const ScaleConfig& config) {
    if (auto st = config.Validate(); !st) return st.error();
    if (!config.enabled()) return Error{ErrorCode::kInternal, "scale.driver is none"};
    if (config.driver == "simulated") return SimulatedScale::Start(config);
    auto driver = ModbusScale::Open(config);
    if (!driver) return driver.error();
    return std::unique_ptr<Scale>(std::move(*driver));
}

}  // namespace boxd
