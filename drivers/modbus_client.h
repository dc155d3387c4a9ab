#pragma once
// ModbusClient: one Modbus TCP or RTU connection (libmodbus) with bounded retries. A transport
// failure (timeout, dropped connection, garbled reply) closes the connection and the next
// attempt reconnects; a Modbus exception reply is the device's answer and is not retried
// (except "busy" and "acknowledge", which mean "ask again"). Errors are TURNTABLE_ERROR with a
// message that names the device and the transaction.

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
};

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
