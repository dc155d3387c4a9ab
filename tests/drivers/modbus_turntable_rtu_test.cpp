// The Modbus turntable driver over Modbus RTU: `boxd sim-turntable --rtu` on one end of a socat
// pseudo-terminal pair, the driver on the other.
#include <gtest/gtest.h>

#include <filesystem>

#include "drivers/modbus_turntable.h"
#include "drivers/sim/turntable_simulator.h"
#include "tests/drivers/sim_turntable_process.h"

namespace boxd::test {
namespace {

bool SocatAvailable() {
    for (const char* dir : {"/usr/bin", "/bin", "/usr/local/bin"}) {
        if (std::filesystem::exists(std::filesystem::path(dir) / "socat")) return true;
    }
    return false;
}

bool WaitForPath(const std::filesystem::path& path, double seconds) {
    const auto start = SteadyClock::now();
    while (SecondsSince(start) < seconds) {
        if (std::filesystem::exists(path)) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
}

class ModbusTurntableRtu : public ::testing::Test {
protected:
    void SetUp() override {
        if (!SocatAvailable()) GTEST_SKIP() << "socat is not installed; RTU tests need a pty pair";
        socat_ = std::make_unique<ChildProcess>(
            std::vector<std::string>{"socat", "pty,raw,echo=0,link=" + (dir_ / "drive").string(),
                                     "pty,raw,echo=0,link=" + (dir_ / "host").string()});
        ASSERT_TRUE(WaitForPath(dir_ / "drive", 5.0) && WaitForPath(dir_ / "host", 5.0))
            << "socat did not create the pty pair";
    }

    void StartSimulator(const std::vector<std::string>& extra) {
        std::vector<std::string> argv{
            BOXD_BINARY, "sim-turntable", "--rtu",      (dir_ / "drive").string(),
            "--baud",    "115200",        "--slave-id", "5"};
        argv.insert(argv.end(), extra.begin(), extra.end());
        sim_ = std::make_unique<ChildProcess>(argv);
        // Ready once it answers a status read on the line.
        ModbusLinkConfig link;
        link.rtu = true;
        link.device = (dir_ / "host").string();
        link.baud = 115200;
        link.slave_id = 5;
        // Long enough to cover the simulator's start-up: a request sent before it listens
        // waits in the pty and gets its reply late, which a short timeout would leave behind
        // on the line for the next client.
        link.response_timeout_ms = 3000;
        link.retries = 0;
        const auto start = SteadyClock::now();
        bool ready = false;
        while (!ready && SecondsSince(start) < 10.0 && sim_->Running()) {
            ModbusClient probe(link);
            ready = probe.ReadRegisters(10, 1).ok();
        }
        ASSERT_TRUE(ready) << "sim-turntable did not answer on " << link.device;
    }

    TurntableConfig RtuConfig() const {
        TurntableConfig c = FastTestConfig(0);
        c.driver = "modbus-rtu";
        c.device = (dir_ / "host").string();
        c.baud = 115200;
        c.slave_id = 5;
        return c;
    }

    void TearDown() override {
        sim_.reset();  // before socat, so the simulator never sees its pty vanish mid-request
        socat_.reset();
    }

    TempDir dir_;
    std::unique_ptr<ChildProcess> socat_;
    std::unique_ptr<ChildProcess> sim_;
};

TEST_F(ModbusTurntableRtu, HomesAndStepsOverASerialLine) {
    StartSimulator({"--speed-dps", "720", "--settle-ms", "10", "--initial-angle-deg", "12"});
    auto table = ModbusTurntable::Open(RtuConfig());
    ASSERT_TRUE(table.ok()) << table.error().message;
    EXPECT_NE((*table)->Describe().find("modbus-rtu"), std::string::npos);
    const auto start = SteadyClock::now();
    for (int k = 0; k < 6; ++k) {
        auto st = (*table)->MoveTo(20.0 * k);
        ASSERT_TRUE(st.ok()) << "pose " << k << ": " << st.error().message;
        EXPECT_NEAR(*(*table)->CurrentAngleDeg(), 20.0 * k, 0.01);
    }
    EXPECT_LT(SecondsSince(start), 5.0);
}

TEST_F(ModbusTurntableRtu, StallFaultIsReportedAndTheTableStopped) {
    StartSimulator({"--speed-dps", "720", "--fault", "stall"});
    auto table = ModbusTurntable::Open(RtuConfig());
    ASSERT_TRUE(table.ok()) << table.error().message;
    const auto start = SteadyClock::now();
    auto st = (*table)->MoveTo(80.0);
    ASSERT_FALSE(st.ok());
    EXPECT_LT(SecondsSince(start), 3.0);
    EXPECT_NE(st.error().message.find("stall (code 1)"), std::string::npos) << st.error().message;
    auto state = (*table)->State();
    ASSERT_TRUE(state.ok());
    EXPECT_FALSE(state->moving);
    EXPECT_NEAR(state->angle_deg, 40.0, 0.01);
}

TEST_F(ModbusTurntableRtu, WithheldReplyIsRetriedAndTheMoveCompletes) {
    StartSimulator({"--speed-dps", "360", "--fault", "drop"});
    auto table = ModbusTurntable::Open(RtuConfig());
    ASSERT_TRUE(table.ok()) << table.error().message;
    auto st = (*table)->MoveTo(90.0);
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_NEAR(*(*table)->CurrentAngleDeg(), 90.0, 0.01);
    EXPECT_GE((*table)->connections_opened(), 2) << "the serial line was not reopened";
}

TEST_F(ModbusTurntableRtu, WrongSlaveIdGetsNoAnswer) {
    StartSimulator({});
    TurntableConfig config = RtuConfig();
    config.slave_id = 9;
    config.retries = 0;
    auto table = ModbusTurntable::Open(config);
    ASSERT_TRUE(table.ok()) << table.error().message;  // a serial port opens without a peer
    const auto start = SteadyClock::now();
    auto st = (*table)->Home();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().message.find("no reply within 200 ms"), std::string::npos)
        << st.error().message;
    EXPECT_LT(SecondsSince(start), 2.0);
}

}  // namespace
}  // namespace boxd::test
