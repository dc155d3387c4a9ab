// The Modbus turntable driver against the real `boxd sim-turntable` binary over Modbus TCP on
// loopback: homing, a full turn, every injected fault, reconnection, stop.
#include "drivers/modbus_turntable.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

#include "drivers/sim/turntable_simulator.h"
#include "tests/drivers/sim_turntable_process.h"
#include "tests/support/run_command.h"

namespace boxd::test {
namespace {

constexpr int kMovingBit = 1;
constexpr int kInPositionBit = 2;

std::unique_ptr<ModbusTurntable> OpenDriver(const TurntableConfig& config) {
    auto driver = ModbusTurntable::Open(config);
    EXPECT_TRUE(driver.ok()) << (driver.ok() ? "" : driver.error().message);
    return driver.ok() ? std::move(*driver) : nullptr;
}

TEST(ModbusTurntable, HomesThenTurnsEighteenStepsAndComesBack) {
    SimTurntableProcess sim(
        {"--speed-dps", "720", "--settle-ms", "20", "--initial-angle-deg", "57.3"});
    ASSERT_GT(sim.port(), 0) << "sim-turntable did not start";
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    SimRegisters regs(sim.port());
    EXPECT_NEAR(regs.AngleDeg(), 57.3, 1e-9);

    const auto start = SteadyClock::now();
    for (int k = 0; k < 18; ++k) {
        const double target = 20.0 * k;
        auto st = table->MoveTo(target);
        ASSERT_TRUE(st.ok()) << "pose " << k << ": " << st.error().message;
        auto angle = table->CurrentAngleDeg();
        ASSERT_TRUE(angle.ok());
        EXPECT_NEAR(*angle, target, 0.01) << "pose " << k;
        auto state = table->State();
        ASSERT_TRUE(state.ok());
        EXPECT_TRUE(state->homed && state->in_position && !state->moving) << "pose " << k;
    }
    // The table accumulates angle: back to 0 is a 340° turn the other way.
    ASSERT_TRUE(table->MoveTo(0.0).ok());
    EXPECT_NEAR(regs.AngleDeg(), 0.0, 0.01);
    EXPECT_LT(SecondsSince(start), 10.0);

    // The driver homed once, before its first move, and sent 19 moves.
    EXPECT_EQ(regs.Read(kSimHomeCountRegister), 1);
    EXPECT_EQ(regs.Read(kSimMoveCountRegister), 19);
    EXPECT_EQ(table->connections_opened(), 1);
}

TEST(ModbusTurntable, AngleBeyondOneTurnIsAnAbsoluteTarget) {
    SimTurntableProcess sim({"--speed-dps", "3600", "--settle-ms", "0"});
    ASSERT_GT(sim.port(), 0);
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    ASSERT_TRUE(table->MoveTo(400.0).ok());
    ASSERT_TRUE(table->MoveTo(-30.5).ok());
    EXPECT_NEAR(*table->CurrentAngleDeg(), -30.5, 0.01);
}

TEST(ModbusTurntable, StallFaultIsATurntableErrorNamingTheFault) {
    SimTurntableProcess sim({"--speed-dps", "720", "--settle-ms", "10", "--fault", "stall"});
    ASSERT_GT(sim.port(), 0);
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    const auto start = SteadyClock::now();
    auto st = table->MoveTo(90.0);
    ASSERT_FALSE(st.ok());
    EXPECT_LT(SecondsSince(start), 3.0);
    EXPECT_EQ(st.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(st.error().message.find("stall (code 1)"), std::string::npos) << st.error().message;
    SimRegisters regs(sim.port());
    EXPECT_FALSE(regs.StatusBit(kMovingBit));
    EXPECT_GE(regs.Read(kSimStopCountRegister), 1) << "no stop command after the fault";
    EXPECT_NEAR(regs.AngleDeg(), 45.0, 0.01);  // the simulator stalls halfway
}

TEST(ModbusTurntable, MoveThatNeverArrivesTimesOutAndIsStopped) {
    SimTurntableProcess sim({"--speed-dps", "720", "--fault", "timeout"});
    ASSERT_GT(sim.port(), 0);
    TurntableConfig config = FastTestConfig(sim.port());
    config.move_timeout_ms = 600;
    auto table = OpenDriver(config);
    ASSERT_TRUE(table);
    const auto start = SteadyClock::now();
    auto st = table->MoveTo(90.0);
    const double elapsed = SecondsSince(start);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(st.error().message.find("not finished within 600 ms"), std::string::npos)
        << st.error().message;
    EXPECT_GE(elapsed, 0.6);
    EXPECT_LT(elapsed, 4.0);
    SimRegisters regs(sim.port());
    EXPECT_FALSE(regs.StatusBit(kMovingBit)) << "the table was left moving";
    EXPECT_FALSE(regs.StatusBit(kInPositionBit));
}

TEST(ModbusTurntable, DroppedConnectionIsRecoveredByReconnecting) {
    SimTurntableProcess sim(
        {"--speed-dps", "360", "--settle-ms", "10", "--fault", "drop", "--fault-after-moves", "1"});
    ASSERT_GT(sim.port(), 0);
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    ASSERT_TRUE(table->MoveTo(20.0).ok());
    EXPECT_EQ(table->connections_opened(), 1);
    const auto start = SteadyClock::now();
    auto st = table->MoveTo(120.0);
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_LT(SecondsSince(start), 3.0);
    EXPECT_EQ(table->connections_opened(), 2);
    EXPECT_NEAR(*table->CurrentAngleDeg(), 120.0, 0.01);
    SimRegisters regs(sim.port());
    EXPECT_EQ(regs.Read(kSimConnectionCountRegister), 3);  // driver twice, then this reader
}

TEST(ModbusTurntable, ExceptionReplyIsAnErrorAndTheTableStaysPut) {
    SimTurntableProcess sim({"--speed-dps", "720", "--fault", "exception"});
    ASSERT_GT(sim.port(), 0);
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    const auto start = SteadyClock::now();
    auto st = table->MoveTo(90.0);
    ASSERT_FALSE(st.ok());
    EXPECT_LT(SecondsSince(start), 3.0);
    EXPECT_EQ(st.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(st.error().message.find("Modbus exception"), std::string::npos) << st.error().message;
    SimRegisters regs(sim.port());
    EXPECT_NEAR(regs.AngleDeg(), 0.0, 0.01);
    EXPECT_FALSE(regs.StatusBit(kMovingBit));
    EXPECT_EQ(regs.Read(kSimMoveCountRegister), 1) << "an exception reply must not be retried";
}

TEST(ModbusTurntable, SlowRepliesAreATimeoutErrorWithinTheRetryBudget) {
    SimTurntableProcess sim({"--speed-dps", "720", "--fault", "slow", "--slow-ms", "700"});
    ASSERT_GT(sim.port(), 0);
    TurntableConfig config = FastTestConfig(sim.port());
    config.retries = 1;
    auto table = OpenDriver(config);
    ASSERT_TRUE(table);
    const auto start = SteadyClock::now();
    auto st = table->MoveTo(90.0);
    ASSERT_FALSE(st.ok());
    // Move command: 2 attempts of 200 ms, then the stop command: at most 2 more.
    EXPECT_LT(SecondsSince(start), 3.0);
    EXPECT_EQ(st.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(st.error().message.find("no reply within 200 ms"), std::string::npos)
        << st.error().message;
    EXPECT_NE(st.error().message.find("2 attempts"), std::string::npos) << st.error().message;
}

TEST(ModbusTurntable, StopRequestEndsAMoveAndLeavesTheTableAtRest) {
    SimTurntableProcess sim({"--speed-dps", "720", "--settle-ms", "10"});
    ASSERT_GT(sim.port(), 0);
    TurntableConfig config = FastTestConfig(sim.port());
    config.speed_dps = 45.0;  // slow enough to interrupt
    auto table = OpenDriver(config);
    ASSERT_TRUE(table);
    ASSERT_TRUE(table->Home().ok());

    std::thread stopper([&table] {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        table->RequestStop();
    });
    const auto start = SteadyClock::now();
    auto st = table->MoveTo(180.0);
    stopper.join();
    ASSERT_FALSE(st.ok());
    EXPECT_LT(SecondsSince(start), 2.0);
    EXPECT_NE(st.error().message.find("stop requested"), std::string::npos) << st.error().message;

    SimRegisters regs(sim.port());
    EXPECT_FALSE(regs.StatusBit(kMovingBit));
    const double angle = regs.AngleDeg();
    EXPECT_GT(angle, 1.0);
    EXPECT_LT(angle, 90.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_NEAR(regs.AngleDeg(), angle, 1e-9) << "the table kept turning after the stop";

    // The request is sticky until cleared; then the table moves again.
    EXPECT_FALSE(table->MoveTo(10.0).ok());
    table->ClearStopRequest();
    EXPECT_TRUE(table->MoveTo(10.0).ok());
}

TEST(ModbusTurntable, StopHaltsATableThatAnotherClientSetMoving) {
    SimTurntableProcess sim({"--speed-dps", "30"});
    ASSERT_GT(sim.port(), 0);
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    ASSERT_TRUE(table->Home().ok());
    SimRegisters regs(sim.port());
    regs.Write(1, 0);
    regs.Write(2, 9000);  // 90.00°
    regs.Write(3, 300);   // 30 °/s
    regs.Write(0, 1);     // move
    EXPECT_TRUE(regs.StatusBit(kMovingBit));
    ASSERT_TRUE(table->Stop().ok());
    auto state = table->State();
    ASSERT_TRUE(state.ok());
    EXPECT_FALSE(state->moving);
    EXPECT_FALSE(regs.StatusBit(kMovingBit));
}

TEST(ModbusTurntable, FaultHitsOnlyAfterTheGivenNumberOfMoves) {
    SimTurntableProcess sim(
        {"--speed-dps", "720", "--settle-ms", "5", "--fault", "stall", "--fault-after-moves", "2"});
    ASSERT_GT(sim.port(), 0);
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    EXPECT_TRUE(table->MoveTo(20.0).ok());
    EXPECT_TRUE(table->MoveTo(40.0).ok());
    auto st = table->MoveTo(60.0);
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().message.find("stall"), std::string::npos) << st.error().message;
}

// One simulator process, several scenarios switched through the special registers.
TEST(ModbusTurntable, SpecialRegistersSwitchFaultsAtRunTime) {
    SimTurntableProcess sim({"--speed-dps", "720", "--settle-ms", "5"});
    ASSERT_GT(sim.port(), 0);
    auto table = OpenDriver(FastTestConfig(sim.port()));
    ASSERT_TRUE(table);
    SimRegisters regs(sim.port());
    ASSERT_TRUE(table->MoveTo(30.0).ok());

    regs.Write(kSimFaultModeRegister, static_cast<int>(SimulatedFault::kException));
    auto exception = table->MoveTo(60.0);
    ASSERT_FALSE(exception.ok());
    EXPECT_NE(exception.error().message.find("Modbus exception"), std::string::npos);

    regs.Write(kSimFaultModeRegister, static_cast<int>(SimulatedFault::kStall));
    auto stall = table->MoveTo(90.0);
    ASSERT_FALSE(stall.ok());
    EXPECT_NE(stall.error().message.find("stall (code 1)"), std::string::npos);
    EXPECT_TRUE(regs.StatusBit(3)) << "the stall fault is latched in the drive";

    // With the fault disarmed the driver clears the latched fault and moves again.
    regs.Write(kSimFaultModeRegister, 0);
    auto st = table->MoveTo(90.0);
    ASSERT_TRUE(st.ok()) << st.error().message;
    EXPECT_NEAR(regs.AngleDeg(), 90.0, 0.01);
    EXPECT_FALSE(regs.StatusBit(3));
}

TEST(ModbusTurntable, ReadOnlyRegistersAndBadCommandsGetExceptions) {
    SimTurntableProcess sim({});
    ASSERT_GT(sim.port(), 0);
    ModbusLinkConfig link;
    link.port = sim.port();
    link.retries = 3;
    ModbusClient client(link);
    auto status_write = client.WriteRegisters(10, {1});
    ASSERT_FALSE(status_write.ok());
    EXPECT_NE(status_write.error().message.find("Modbus exception"), std::string::npos);
    auto bad_command = client.WriteRegisters(0, {9});
    ASSERT_FALSE(bad_command.ok());
    EXPECT_NE(bad_command.error().message.find("Modbus exception"), std::string::npos);
    auto out_of_map = client.ReadRegisters(500, 2);
    ASSERT_FALSE(out_of_map.ok());
    EXPECT_NE(out_of_map.error().message.find("Illegal data address"), std::string::npos)
        << out_of_map.error().message;
    EXPECT_EQ(client.connections_opened(), 1) << "an exception must not cause a reconnect";
}

TEST(ModbusTurntable, ProfileScalingAndSignMapADifferentDrive) {
    SimTurntableProcess sim({"--speed-dps", "720", "--settle-ms", "5"});
    ASSERT_GT(sim.port(), 0);
    TurntableConfig config = FastTestConfig(sim.port());
    // A drive counting clockwise: boxd's +20° is the drive's -20°.
    config.profile.angle_units_per_deg = -100.0;
    config.profile.speed_register = -1;       // no speed register: the drive's own speed
    config.profile.fault_code_register = -1;  // no fault code register
    auto table = OpenDriver(config);
    ASSERT_TRUE(table);
    ASSERT_TRUE(table->MoveTo(20.0).ok());
    EXPECT_NEAR(*table->CurrentAngleDeg(), 20.0, 0.01);
    SimRegisters regs(sim.port());
    EXPECT_NEAR(regs.AngleDeg(), -20.0, 0.01);
}

TEST(ModbusTurntable, UnreachableDriveIsAnErrorNotAHang) {
    int port = 0;
    {
        SimTurntableProcess sim({});
        port = sim.port();
    }  // the simulator is gone; nothing listens on its port any more
    ASSERT_GT(port, 0);
    const auto start = SteadyClock::now();
    auto driver = ModbusTurntable::Open(FastTestConfig(port));
    ASSERT_FALSE(driver.ok());
    EXPECT_EQ(driver.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(driver.error().message.find("cannot connect"), std::string::npos);
    EXPECT_LT(SecondsSince(start), 2.0);
}

TEST(ModbusTurntable, DriveThatDiesMidSessionGivesAnErrorWithinTheRetryBudget) {
    auto sim = std::make_unique<SimTurntableProcess>(std::vector<std::string>{});
    ASSERT_GT(sim->port(), 0);
    auto table = OpenDriver(FastTestConfig(sim->port()));
    ASSERT_TRUE(table);
    ASSERT_TRUE(table->Home().ok());
    sim.reset();
    const auto start = SteadyClock::now();
    auto st = table->MoveTo(20.0);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kTurntableError);
    EXPECT_NE(st.error().message.find("3 attempts"), std::string::npos) << st.error().message;
    EXPECT_LT(SecondsSince(start), 3.0);
}

TEST(SimTurntable, StopsCleanlyOnSigterm) {
    SimTurntableProcess sim({});
    ASSERT_GT(sim.port(), 0);
    EXPECT_EQ(sim.process().Terminate(), 0);
}

TEST(SimTurntable, RejectsAnUnknownFault) {
    auto out = RunCommand({BOXD_BINARY, "sim-turntable", "--port", "0", "--fault", "gremlins"});
    EXPECT_EQ(out.exit_code, 2);
    EXPECT_NE(out.err.find("sim-turntable.fault"), std::string::npos) << out.err;
}

}  // namespace
}  // namespace boxd::test
