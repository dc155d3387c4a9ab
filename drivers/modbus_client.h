#pragma once
// ModbusClient: one Modbus TCP or RTU connection (libmodbus) with bounded retries. A transport
// failure (timeout, dropped connection, garbled reply) closes the connection and the next
// attempt reconnects; a Modbus exception reply is the device's answer and is not retried
// (except "busy" and "acknowledge", which mean "ask again"). Errors carry the link's device
// error code (TURNTABLE_ERROR for a drive, SCALE_ERROR for a weighing indicator) and a message
// that names the device and the transaction.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/result.h"

namespace boxd {

struct ModbusLinkConfig {
    bool rtu = false;
    std::string host = "127.0.0.1";  // TCP
    int port = 502;
    std::string device;  // RTU
    int baud = 19200;
    char parity = 'N';
    int data_bits = 8;
    int stop_bits = 1;
    int slave_id = 1;
    int response_timeout_ms = 300;
    int retries = 2;
    int retry_delay_ms = 50;
    ErrorCode error_code = ErrorCode::kTurntableError;  // the code of the link's errors
};

// Returns the link settings of a device's config section (a turntable's or a scale's: the same
// key names), as RTU when `rtu`, its errors carrying `code`.
template <typename DeviceConfig>
ModbusLinkConfig LinkConfigOf(const DeviceConfig& c, bool rtu, ErrorCode code) {
    ModbusLinkConfig link;
    link.rtu = rtu;
    link.host = c.host;
    link.port = c.port;
    link.device = c.device;
    link.baud = c.baud;
    link.parity = c.parity.empty() ? 'N' : c.parity[0];
    link.data_bits = c.data_bits;
    link.stop_bits = c.stop_bits;
    link.slave_id = c.slave_id;
    link.response_timeout_ms = c.response_timeout_ms;
    link.retries = c.retries;
    link.retry_delay_ms = c.retry_delay_ms;
    link.error_code = code;
    return link;
}

class ModbusClient {
public:
    explicit ModbusClient(ModbusLinkConfig config);
    ~ModbusClient();
    ModbusClient(const ModbusClient&) = delete;
    ModbusClient& operator=(const ModbusClient&) = delete;

    // Opens the connection now (it is also opened on demand); returns the error of the attempt.
    Status Connect();
    void Close();

    // Returns `count` holding registers from `address`. `what` names the transaction in errors
    // ("status"); the register range is always named.
    Result<std::vector<uint16_t>> ReadRegisters(int address, int count,
                                                const std::string& what = "");
    // Writes `values` to consecutive holding registers from `address` (function 16).
    Status WriteRegisters(int address, const std::vector<uint16_t>& values,
                          const std::string& what = "");

    // Returns "modbus-tcp 127.0.0.1:5020 slave 1" or "modbus-rtu /dev/ttyUSB0 19200 8N1 slave 1".
    std::string Describe() const;
    // Returns the number of connections opened so far (reconnects included).
    int connections_opened() const { return connections_opened_; }

private:
    struct Context;
    // Opens the connection if it is closed; on failure returns false and sets `why`.
    bool OpenLink(std::string& why);
    template <typename Fn>
    Status Transact(const std::string& what, Fn&& fn);

    ModbusLinkConfig config_;
    std::unique_ptr<Context> ctx_;
    int connections_opened_ = 0;
};

}  // namespace boxd
