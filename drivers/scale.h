#pragma once
// Scale: the weighing indicator under the turntable, read over Modbus TCP or RTU (libmodbus).
// One small interface, like the turntable's: a reading of the indicator (its weight and its
// status flags) and the zero and tare commands. ScaleProfile maps an indicator's registers;
// its defaults are what the simulated indicator (drivers/sim/scale_simulator.h) serves.
//
// Units: an indicator shows kg or lb (`unit`); every weight here is in that unit. Its register
// holds whole counts of `count` (e.g. 0.001 kg), and it is verified to its division `division`
// (e, e.g. 0.005 kg) between its minimum load `min_weight` (Min) and its capacity (Max).
//
// Errors are boxd::Error{code = "SCALE_ERROR", message = "<device>: <what happened>"}.

#include <atomic>
#include <memory>
#include <string>

#include "drivers/turntable_profile.h"
#include "pipeline/core/result.h"

namespace YAML {
class Node;
}

namespace boxd {

// One reading of the indicator.
struct ScaleReading {
    double weight = 0.0;     // gross or net (ScaleConfig::read), in the scale's unit
    bool stable = false;     // the indicator's own "no motion" flag
    bool overload = false;   // above its capacity
    bool underload = false;  // below zero beyond its range
};

class Scale {
public:
    virtual ~Scale() = default;
    // Returns the indicator's weight and flags, read in one transaction.
    virtual Result<ScaleReading> Read() = 0;
    // Sends the zero command (the empty platform becomes zero).
    virtual Status Zero() = 0;
    // Sends the tare command (the load on the platform becomes the tare).
    virtual Status Tare() = 0;
    // Returns a one-line description, e.g. "modbus-tcp 127.0.0.1:5021 slave 1".
    virtual std::string Describe() const = 0;
};

// Where an indicator keeps what boxd reads and writes (holding registers).
struct ScaleProfile {
    int weight_register = 0;  // the gross weight, signed 32-bit over two registers
    int net_register = 2;     // the net weight, signed 32-bit over two registers
    WordOrder word_order = WordOrder::kHighFirst;
    int status_register = 4;
    int stable_bit = 0;
    int overload_bit = 1;
    int underload_bit = 2;
    int command_register = 5;
    int command_zero = 1;
    int command_tare = 2;

    // Returns an error naming the first invalid field ("scale.registers.<field>: ...").
    Status Validate() const;
};

// The simulated indicator's parcel and faults (`scale.simulated`).
struct SimulatedScaleConfig {
    double load = 2.5;  // what stands on the platform, in the scale's unit
    // none | no_answer | never_stable | overload | drifting_zero
    std::string fault = "none";
    double noise_divisions = 0.2;  // reading noise, standard deviation in divisions
    int settle_ms = 600;           // the platform's ring-down after a load is put on
};

// The `scale:` section of the YAML config (field names are the YAML keys).
struct ScaleConfig {
    // none (no scale) | modbus-tcp | modbus-rtu | simulated (a simulated indicator served over
    // Modbus TCP on 127.0.0.1 by a thread of boxd's own).
    std::string driver = "none";
    std::string host = "127.0.0.1";
    int port = 502;
    std::string device = "/dev/ttyUSB1";
    int baud = 9600;
    std::string parity = "N";
    int data_bits = 8;
    int stop_bits = 1;
    int slave_id = 1;
    int response_timeout_ms = 300;
    int retries = 2;
    int retry_delay_ms = 50;

    std::string unit = "kg";     // kg | lb
    double count = 0.001;        // the weight of one register count
    double division = 0.005;     // the verification division e
    double min_weight = 0.1;     // Min: lighter loads are not stated (20 e by default)
    double capacity = 60.0;      // Max
    std::string read = "gross";  // gross | net

    // The motion criterion: a weight is taken once every reading of the last `stable_time_ms`
    // lies within `stable_band_divisions` of each other (and the indicator says stable, with
    // use_stable_flag); none within `timeout_ms` is a SCALE_ERROR.
    int stable_time_ms = 1000;
    double stable_band_divisions = 1.0;
    bool use_stable_flag = true;
    int poll_interval_ms = 50;
    int timeout_ms = 10000;

    ScaleProfile registers;
    SimulatedScaleConfig simulated;

    bool enabled() const { return driver != "none"; }
    // Returns an error naming the first invalid field ("scale.<field>: ..."), or Ok.
    Status Validate() const;
};

// Returns the config read from a `scale:` node (absent or null: no scale). Unknown keys, wrong
// types and invalid values are errors naming the key.
Result<ScaleConfig> ParseScaleConfig(const YAML::Node& node);

// Returns the scale `config.driver` names, connected, or SCALE_ERROR; config.enabled().
Result<std::unique_ptr<Scale>> MakeScale(const ScaleConfig& config);

}  // namespace boxd
