#pragma once
// ScaleSimulator: a weighing indicator served over Modbus (TCP or RTU) with the register map of
// ScaleProfile's defaults — the simulated station's scale. The load on its platform rings down
// after it is put on (a damped oscillation over `settle_ms`), the reading carries noise and is
// shown in whole divisions, and the indicator sets its own stable flag once the platform is
// still. Faults (SimulatedScaleConfig::fault) make a client's error paths real:
//   no_answer     - requests are received and never answered.
//   never_stable  - the platform keeps swinging by a few divisions; the flag never comes.
//   overload      - the overload flag is set (a load above Max, something leaning on it).
//   drifting_zero - the zero creeps by 6 divisions a second from the moment the load is put on.
//
// Special holding registers beyond the indicator's map (never subject to the faults):
//   20..21 (rw) the load, signed 32-bit counts (high word first); writing it puts the load on
//               again (the ring-down starts anew).
//   22     (rw) the fault: 0 none, 1 no_answer, 2 never_stable, 3 overload, 4 drifting_zero.
//   23     (r)  weight readings answered.    24 (r) zero commands.    25 (r) tare commands.

#include <atomic>
#include <memory>
#include <string>

#include "drivers/scale.h"
#include "pipeline/core/result.h"

namespace boxd {

inline constexpr int kSimScaleLoadRegister = 20;
inline constexpr int kSimScaleFaultRegister = 22;
inline constexpr int kSimScaleReadCountRegister = 23;
inline constexpr int kSimScaleZeroCountRegister = 24;
inline constexpr int kSimScaleTareCountRegister = 25;

// Returns the fault number of a `scale.simulated.fault` name, or INVALID_INPUT naming the names.
Result<int> SimulatedScaleFaultNumber(const std::string& name);

class ScaleSimulator {
public:
    // The indicator of `config` (its unit, count, division, capacity, slave id) with the load and
    // fault of config.simulated.
    explicit ScaleSimulator(const ScaleConfig& config);
    ~ScaleSimulator();
    ScaleSimulator(const ScaleSimulator&) = delete;
    ScaleSimulator& operator=(const ScaleSimulator&) = delete;

    // Listens for Modbus TCP on host:port (port 0 picks a free one).
    Status ListenTcp(const std::string& host, int port);
    int port() const;
    // Opens the serial device for Modbus RTU.
    Status OpenRtu(const std::string& device, int baud, char parity, int data_bits, int stop_bits);
    // Serves until `stop` becomes true.
    Status Serve(const std::atomic<bool>& stop);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace boxd
