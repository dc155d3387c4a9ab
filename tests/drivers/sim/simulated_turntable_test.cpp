// The simulator's motion model on a synthetic clock, and the "simulated" turntable driver
// driver (TurntableSimulator on a thread, driven over Modbus TCP on loopback).
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "drivers/sim/simulated_drive.h"
#include "drivers/sim/turntable_simulator.h"
#include "drivers/turntable.h"
#include "tests/drivers/sim_turntable_process.h"

namespace boxd {
namespace {

using std::chrono::milliseconds;

TEST(SimulatedDrive, MovesAtSpeedThenSettlesIntoPosition) {
    SimulatedDrive drive(10.0);
    const auto t0 = SimClock::now();
    drive.Home(100.0, 0, t0);
    drive.Advance(t0 + milliseconds(50));
    EXPECT_NEAR(drive.status().angle_deg, 5.0, 1e-6);
    drive.Advance(t0 + milliseconds(200));
    ASSERT_TRUE(drive.status().homed);
    EXPECT_DOUBLE_EQ(drive.status().angle_deg, 0.0);

    const auto t1 = t0 + milliseconds(300);
    drive.Move(90.0, 90.0, 100, MoveMisbehaviour::kNone, t1);
    drive.Advance(t1 + milliseconds(500));
    EXPECT_NEAR(drive.status().angle_deg, 45.0, 1e-6);
    EXPECT_TRUE(drive.status().moving);
    EXPECT_FALSE(drive.status().in_position);
    drive.Advance(t1 + milliseconds(1050));
    EXPECT_DOUBLE_EQ(drive.status().angle_deg, 90.0);
    EXPECT_FALSE(drive.status().moving);
    EXPECT_FALSE(drive.status().in_position) << "still settling";
    drive.Advance(t1 + milliseconds(1101));
    EXPECT_TRUE(drive.status().in_position);
}

TEST(SimulatedDrive, MoveWithoutHomingFaultsNotHomed) {
    SimulatedDrive drive(0.0);
    const auto t0 = SimClock::now();
    drive.Move(20.0, 90.0, 0, MoveMisbehaviour::kNone, t0);
    EXPECT_TRUE(drive.status().fault);
    EXPECT_EQ(drive.status().fault_code, 3);
    EXPECT_FALSE(drive.status().moving);
}

TEST(SimulatedDrive, StallStopsHalfwayWithFaultCodeOne) {
    SimulatedDrive drive(0.0);
    const auto t0 = SimClock::now();
    drive.Home(100.0, 0, t0);
    drive.Move(-60.0, 100.0, 0, MoveMisbehaviour::kStall, t0 + milliseconds(1));
    drive.Advance(t0 + milliseconds(2000));
    EXPECT_TRUE(drive.status().fault);
    EXPECT_EQ(drive.status().fault_code, 1);
    EXPECT_FALSE(drive.status().moving);
    EXPECT_NEAR(drive.status().angle_deg, -30.0, 1e-6);
    drive.Move(0.0, 100.0, 0, MoveMisbehaviour::kNone, t0 + milliseconds(2001));
    EXPECT_FALSE(drive.status().moving) << "a faulted drive ignores motion commands";
    drive.ClearFault();
    EXPECT_FALSE(drive.status().fault);
}

TEST(SimulatedDrive, NeverArrivingMoveKeepsMovingUntilStopped) {
    SimulatedDrive drive(0.0);
    const auto t0 = SimClock::now();
    drive.Home(100.0, 0, t0);
    drive.Move(30.0, 100.0, 0, MoveMisbehaviour::kNeverArrive, t0 + milliseconds(1));
    drive.Advance(t0 + milliseconds(5000));
    EXPECT_TRUE(drive.status().moving);
    EXPECT_FALSE(drive.status().in_position);
    EXPECT_NEAR(drive.status().angle_deg, 29.0, 1e-6);
    drive.Stop(t0 + milliseconds(5001));
    EXPECT_FALSE(drive.status().moving);
    EXPECT_FALSE(drive.busy());
}

TEST(SimulatedTurntableDriver, MovesOverLoopbackModbus) {
    TurntableConfig config = test::FastTestConfig(0);
    config.driver = "simulated";
    config.simulator_binary = BOXD_BINARY;  // this process is the test, not boxd
    auto table = MakeTurntable(config);
    ASSERT_TRUE(table.ok()) << table.error().message;
    EXPECT_NE((*table)->Describe().find("simulated, modbus-tcp 127.0.0.1:"), std::string::npos)
        << (*table)->Describe();
    for (double angle : {0.0, 20.0, 40.0}) {
        auto st = (*table)->MoveTo(angle);
        ASSERT_TRUE(st.ok()) << st.error().message;
        EXPECT_NEAR(*(*table)->CurrentAngleDeg(), angle, 0.01);
    }
}

TEST(TurntableSimulatorInProcess, ServesSeveralClientsAndStopsOnRequest) {
    TurntableSimulatorConfig sim_config;
    sim_config.max_speed_dps = 720.0;
    sim_config.settle_ms = 5;
    TurntableSimulator simulator(sim_config);
    ASSERT_TRUE(simulator.ListenTcp("127.0.0.1", 0).ok());
    std::atomic<bool> stop{false};
    std::thread server([&] { EXPECT_TRUE(simulator.Serve(stop).ok()); });

    TurntableConfig config = test::FastTestConfig(simulator.port());
    auto a = MakeTurntable(config);
    auto b = MakeTurntable(config);
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_TRUE((*a)->MoveTo(50.0).ok());
    auto seen_by_b = (*b)->CurrentAngleDeg();
    ASSERT_TRUE(seen_by_b.ok());
    EXPECT_NEAR(*seen_by_b, 50.0, 0.01);

    const auto start = test::SteadyClock::now();
    stop.store(true);
    server.join();
    EXPECT_LT(test::SecondsSince(start), 1.0);
}

TEST(TurntableSimulatorConfig, ValidateNamesTheField) {
    TurntableSimulatorConfig c;
    c.max_speed_dps = 0.0;
    auto st = c.Validate();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().message.find("max_speed_dps"), std::string::npos);
    auto fault = ParseSimulatedFault("slow");
    ASSERT_TRUE(fault.ok());
    EXPECT_EQ(*fault, SimulatedFault::kSlow);
    EXPECT_STREQ(SimulatedFaultName(SimulatedFault::kDrop), "drop");
    EXPECT_FALSE(ParseSimulatedFault("gremlins").ok());
}

}  // namespace
}  // namespace boxd
