#pragma once
// ModbusServer: the serving side of a simulated Modbus device (libmodbus), TCP or RTU. It owns
// the listening socket or the serial line and the connected clients, and hands every request
// to the device's handler; between requests (at least every 10 ms) it calls the device's tick
// so that its model runs in real time. The turntable simulator and the scale simulator are
// devices served this way.

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pipeline/core/result.h"

typedef struct _modbus modbus_t;

namespace boxd {

class ModbusServer {
public:
    // Answers one request of `length` bytes on `ctx` (modbus_reply or modbus_reply_exception);
    // returns false to close the client's connection without a reply (on RTU: no reply).
    using Handler = std::function<bool(modbus_t* ctx, const uint8_t* request, int length)>;
    using Tick = std::function<void()>;

    // `name` prefixes the log lines and errors ("sim-turntable").
    explicit ModbusServer(std::string name);
    ~ModbusServer();
    ModbusServer(const ModbusServer&) = delete;
    ModbusServer& operator=(const ModbusServer&) = delete;

    // Listens for Modbus TCP on host:port (port 0 picks a free one); returns the error if not.
    Status ListenTcp(const std::string& host, int port);
    // Returns the TCP port listened on (after ListenTcp).
    int port() const { return port_; }
    // Opens the serial device for Modbus RTU as slave `slave_id`; returns the error if not.
    Status OpenRtu(const std::string& device, int baud, char parity, int data_bits, int stop_bits,
                   int slave_id);
    // Returns the number of TCP connections accepted so far.
    int connections_accepted() const { return connections_accepted_; }

    // Serves requests through `handle` until `stop` becomes true, calling `tick` before each
    // request and at least every 10 ms; returns the error that ended serving early, if any.
    Status Serve(const std::atomic<bool>& stop, const Handler& handle, const Tick& tick);

private:
    Status ServeTcpOnce(const Handler& handle, const Tick& tick);
    Status ServeRtuOnce(const Handler& handle, const Tick& tick);
    void CloseClient(std::size_t i);

    std::string name_;
    modbus_t* ctx_ = nullptr;
    bool rtu_ = false;
    int listen_fd_ = -1;
    int port_ = 0;
    int connections_accepted_ = 0;
    std::vector<int> clients_;
};

}  // namespace boxd
