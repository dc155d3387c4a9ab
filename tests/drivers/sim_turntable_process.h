#pragma once
// Test fixture helpers for the turntable tests: the real `boxd sim-turntable` binary as a child
// process (tests/support/child_process.h), a test driver config that keeps the suite fast, and
// raw register access to the simulator. Header-only: tests/CMake builds only *_test.cpp files.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "drivers/modbus_client.h"
#include "drivers/turntable.h"
#include "tests/support/child_process.h"
#include "tests/support/temp_dir.h"

namespace boxd::test {

using SteadyClock = std::chrono::steady_clock;

inline double SecondsSince(SteadyClock::time_point start) {
    return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

// A driver config for the simulator: fast table, short timeouts, every wait bounded.
inline TurntableConfig FastTestConfig(int port) {
    TurntableConfig c;
    c.driver = "modbus-tcp";
    c.host = "127.0.0.1";
    c.port = port;
    c.response_timeout_ms = 200;
    c.retries = 2;
    c.retry_delay_ms = 20;
    c.poll_interval_ms = 5;
    c.move_timeout_ms = 2000;
    c.home_timeout_ms = 3000;
    c.stop_timeout_ms = 1000;
    c.speed_dps = 360.0;
    c.angle_tolerance_deg = 0.05;
    return c;
}

// Raw register access to the simulator (its own connection, beside the driver's).
class SimRegisters {
public:
    explicit SimRegisters(int port) : client_(Link(port)) {}

    int Read(int address) {
        auto r = client_.ReadRegisters(address, 1);
        EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
        return r.ok() ? (*r)[0] : -1;
    }
    void Write(int address, int value) {
        auto st = client_.WriteRegisters(address, {static_cast<uint16_t>(value)});
        EXPECT_TRUE(st.ok()) << (st.ok() ? "" : st.error().message);
    }
    // Returns the simulator's status register bit `bit` (SPEC 8: 0 homed, 1 moving, ...).
    bool StatusBit(int bit) { return ((Read(10) >> bit) & 1) != 0; }
    // Returns the simulator's current angle (registers 11-12, 0.01°).
    double AngleDeg() {
        auto r = client_.ReadRegisters(11, 2);
        EXPECT_TRUE(r.ok());
        if (!r.ok()) return -1e9;
        return static_cast<int32_t>((uint32_t{(*r)[0]} << 16) | (*r)[1]) / 100.0;
    }

private:
    static ModbusLinkConfig Link(int port) {
        ModbusLinkConfig link;
        link.host = "127.0.0.1";
        link.port = port;
        link.response_timeout_ms = 2000;
        return link;
    }
    ModbusClient client_;
};

}  // namespace boxd::test
