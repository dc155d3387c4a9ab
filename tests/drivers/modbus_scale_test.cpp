// The Modbus scale driver against the simulated indicator, over real Modbus TCP on loopback
// (modbus_tcp_listen in the simulator's ModbusServer) and over Modbus RTU on a socat
// pseudo-terminal pair: readings, the zero and tare commands, and each of the indicator's
// faults as the weighing meets them.
#include "drivers/modbus_scale.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

#include "drivers/modbus_client.h"
#include "drivers/sim/scale_simulator.h"
#include "drivers/weighing.h"
#include "tests/support/child_process.h"
#include "tests/support/expect_error.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

ScaleConfig IndicatorConfig(double load, const std::string& fault) {
    ScaleConfig c;
    c.driver = "modbus-tcp";
    c.division = 0.005;
    c.count = 0.001;
    c.capacity = 30.0;
    c.stable_time_ms = 300;
    c.poll_interval_ms = 20;
    c.timeout_ms = 1500;
    c.response_timeout_ms = 200;
    c.retries = 1;
    c.simulated.load = load;
    c.simulated.fault = fault;
    c.simulated.settle_ms = 400;
    return c;
}

// The simulated indicator on a thread of the test, on a free loopback port.
class Indicator {
public:
    explicit Indicator(const ScaleConfig& config) : sim_(config) {
        listening_ = sim_.ListenTcp("127.0.0.1", 0).ok();
        if (listening_) thread_ = std::thread([this] { (void)sim_.Serve(stop_); });
    }
    ~Indicator() {
        stop_ = true;
        if (thread_.joinable()) thread_.join();
    }
    bool listening() const { return listening_; }
    int port() const { return sim_.port(); }

private:
    ScaleSimulator sim_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
    bool listening_ = false;
};

ScaleConfig ClientOf(ScaleConfig c, const Indicator& indicator) {
    c.host = "127.0.0.1";
    c.port = indicator.port();
    return c;
}

TEST(ModbusScale, WeighsTheLoadOnceThePlatformIsStill) {
    const ScaleConfig config = IndicatorConfig(3.215, "none");
    Indicator indicator(config);
    ASSERT_TRUE(indicator.listening());
    auto scale = ModbusScale::Open(ClientOf(config, indicator));
    ASSERT_TRUE(scale.ok()) << scale.error().message;
    const auto t0 = std::chrono::steady_clock::now();
    Result<Weighing> w = WeighStable(**scale, config);
    ASSERT_TRUE(w.ok()) << w.error().message;
    ASSERT_TRUE(w->value.has_value());
    EXPECT_NEAR(*w->value, 3.215, 1e-9);
    // The platform rings for its settle time after the load went on; a weight comes after it.
    const double waited_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_GE(waited_ms, 300.0);
    EXPECT_NE(w->scale.find("modbus-tcp 127.0.0.1:"), std::string::npos);
}

TEST(ModbusScale, TareMakesTheNetZeroAndZeroTheGross) {
    ScaleConfig config = IndicatorConfig(1.5, "none");
    Indicator indicator(config);
    ASSERT_TRUE(indicator.listening());
    config.read = "net";
    auto scale = ModbusScale::Open(ClientOf(config, indicator));
    ASSERT_TRUE(scale.ok()) << scale.error().message;
    ASSERT_TRUE(WeighStable(**scale, config).ok());
    ASSERT_TRUE((*scale)->Tare().ok());
    Result<Weighing> net = WeighStable(**scale, config);
    ASSERT_TRUE(net.ok()) << net.error().message;
    EXPECT_FALSE(net->value.has_value()) << "a tared load reads about zero net, below Min";
    config.read = "gross";
    auto gross_scale = ModbusScale::Open(ClientOf(config, indicator));
    ASSERT_TRUE(gross_scale.ok());
    Result<Weighing> gross = WeighStable(**gross_scale, config);
    ASSERT_TRUE(gross.ok() && gross->value.has_value());
    EXPECT_NEAR(*gross->value, 1.5, 1e-9);
    ASSERT_TRUE((*gross_scale)->Zero().ok());
    Result<ScaleReading> zeroed = (*gross_scale)->Read();
    ASSERT_TRUE(zeroed.ok());
    EXPECT_NEAR(zeroed->weight, 0.0, 2 * config.division);
    // The indicator counted both commands (its special registers 24 and 25).
    ModbusClient raw(LinkConfigOf(ClientOf(config, indicator), false, ErrorCode::kScaleError));
    auto counts = raw.ReadRegisters(kSimScaleZeroCountRegister, 2);
    ASSERT_TRUE(counts.ok());
    EXPECT_EQ((*counts)[0], 1);
    EXPECT_EQ((*counts)[1], 1);
}

TEST(ModbusScale, EachFaultEndsTheWeighingWithASpecificScaleError) {
    const struct {
        const char* fault;
        const char* says;
    } cases[] = {{"no_answer", "no reply within 200 ms"},
                 {"never_stable", "never settled"},
                 {"overload", "overload"},
                 {"drifting_zero", "drifting zero"}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.fault);
        const ScaleConfig config = IndicatorConfig(2.0, c.fault);
        Indicator indicator(config);
        ASSERT_TRUE(indicator.listening());
        auto scale = ModbusScale::Open(ClientOf(config, indicator));
        ASSERT_TRUE(scale.ok()) << scale.error().message;
        Result<Weighing> w = WeighStable(**scale, config);
        test::ExpectError(w, ErrorCode::kScaleError);
        EXPECT_NE(w.error().message.find(c.says), std::string::npos) << w.error().message;
        EXPECT_NE(w.error().message.find("modbus-tcp 127.0.0.1:"), std::string::npos);
    }
}

TEST(ModbusScale, AFaultClearedAtTheIndicatorWeighsAgain) {
    ScaleConfig config = IndicatorConfig(0.75, "overload");
    Indicator indicator(config);
    ASSERT_TRUE(indicator.listening());
    auto scale = ModbusScale::Open(ClientOf(config, indicator));
    ASSERT_TRUE(scale.ok());
    test::ExpectError(WeighStable(**scale, config), ErrorCode::kScaleError);
    ModbusClient raw(LinkConfigOf(ClientOf(config, indicator), false, ErrorCode::kScaleError));
    ASSERT_TRUE(raw.WriteRegisters(kSimScaleFaultRegister, {0}).ok());
    Result<Weighing> w = WeighStable(**scale, config);
    ASSERT_TRUE(w.ok()) << w.error().message;
    EXPECT_NEAR(*w->value, 0.75, 1e-9);
    // The indicator's own registers are not writable: its exception is the driver's error.
    auto refused = raw.WriteRegisters(0, {1});
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().code, ErrorCode::kScaleError);
    EXPECT_NE(refused.error().message.find("Modbus exception"), std::string::npos);
}

bool SocatAvailable() {
    return std::filesystem::exists("/usr/bin/socat") || std::filesystem::exists("/bin/socat");
}

TEST(ModbusScaleRtu, WeighsOverASerialLine) {
    if (!SocatAvailable()) GTEST_SKIP() << "socat is not installed; RTU tests need a pty pair";
    test::TempDir dir;
    test::ChildProcess socat({"socat", "pty,raw,echo=0,link=" + (dir.path() / "scale").string(),
                              "pty,raw,echo=0,link=" + (dir.path() / "host").string()});
    for (int i = 0; i < 500 && !std::filesystem::exists(dir.path() / "host"); ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_TRUE(std::filesystem::exists(dir.path() / "scale"));
    ScaleConfig config = IndicatorConfig(12.345, "none");
    config.slave_id = 7;
    ScaleSimulator sim(config);
    ASSERT_TRUE(sim.OpenRtu((dir.path() / "scale").string(), 115200, 'E', 8, 1).ok());
    std::atomic<bool> stop{false};
    std::thread served([&] { (void)sim.Serve(stop); });
    config.driver = "modbus-rtu";
    config.device = (dir.path() / "host").string();
    config.baud = 115200;
    config.parity = "E";
    config.response_timeout_ms = 1000;
    auto scale = ModbusScale::Open(config);
    ASSERT_TRUE(scale.ok()) << scale.error().message;
    Result<Weighing> w = WeighStable(**scale, config);
    stop = true;
    served.join();
    ASSERT_TRUE(w.ok()) << w.error().message;
    EXPECT_NEAR(*w->value, 12.345, 1e-9);
    EXPECT_NE(w->scale.find("modbus-rtu"), std::string::npos);
}

}  // namespace
}  // namespace boxd
