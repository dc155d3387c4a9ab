#include "drivers/sim/modbus_server.h"

#include <arpa/inet.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <spdlog/spdlog.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>
#include <vector>

namespace boxd {

namespace {

constexpr int kPollSliceMs = 10;

// Waits up to one poll slice for `fds` to become readable; returns select's answer (-1 with
// errno) and the readable set in `readable`.
int WaitReadable(const std::vector<int>& fds, fd_set& readable) {
    FD_ZERO(&readable);
    int max_fd = -1;
    for (int fd : fds) {
        FD_SET(fd, &readable);
        max_fd = std::max(max_fd, fd);
    }
    timeval timeout{0, kPollSliceMs * 1000};
    return select(max_fd + 1, &readable, nullptr, nullptr, &timeout);
}

}  // namespace

ModbusServer::ModbusServer(std::string name) : name_(std::move(name)) {}

ModbusServer::~ModbusServer() {
    for (int fd : clients_) close(fd);
    if (listen_fd_ >= 0) close(listen_fd_);
    if (ctx_) {
        if (rtu_) modbus_close(ctx_);
        modbus_free(ctx_);
    }
}

Status ModbusServer::ListenTcp(const std::string& host, int port) {
    ctx_ = modbus_new_tcp(host.c_str(), port);
    if (!ctx_) {
        return Error{ErrorCode::kInvalidInput,
                     name_ + ": bad listen address " + host + ":" + std::to_string(port)};
    }
    listen_fd_ = modbus_tcp_listen(ctx_, 8);
    if (listen_fd_ < 0) {
        return Error{ErrorCode::kInternal, name_ + ": cannot listen on " + host + ":" +
                                               std::to_string(port) + ": " +
                                               modbus_strerror(errno)};
    }
    sockaddr_in bound{};
    socklen_t len = sizeof(bound);
    getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &len);
    port_ = ntohs(bound.sin_port);
    spdlog::info("{}: listening on {}:{} (Modbus TCP)", name_, host, port_);
    return OkStatus();
}

Status ModbusServer::OpenRtu(const std::string& device, int baud, char parity, int data_bits,
                             int stop_bits, int slave_id) {
    rtu_ = true;
    ctx_ = modbus_new_rtu(device.c_str(), baud, parity, data_bits, stop_bits);
    if (!ctx_) {
        return Error{ErrorCode::kInvalidInput,
                     name_ + ": bad serial settings for " + device + ": " + modbus_strerror(errno)};
    }
    modbus_set_slave(ctx_, slave_id);
    if (modbus_connect(ctx_) == -1) {
        return Error{ErrorCode::kInternal,
                     name_ + ": cannot open " + device + ": " + modbus_strerror(errno)};
    }
    spdlog::info("{}: serving Modbus RTU on {} ({} baud, slave {})", name_, device, baud, slave_id);
    return OkStatus();
}

Status ModbusServer::Serve(const std::atomic<bool>& stop, const Handler& handle, const Tick& tick) {
    if (!ctx_) return Error{ErrorCode::kInternal, name_ + ": not listening"};
    while (!stop.load()) {
        auto st = rtu_ ? ServeRtuOnce(handle, tick) : ServeTcpOnce(handle, tick);
        if (!st) return st;
    }
    return OkStatus();
}

void ModbusServer::CloseClient(std::size_t i) {
    close(clients_[i]);
    clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(i));
}

Status ModbusServer::ServeTcpOnce(const Handler& handle, const Tick& tick) {
    std::vector<int> fds = clients_;
    fds.push_back(listen_fd_);
    fd_set readable;
    const int n = WaitReadable(fds, readable);
    if (n < 0) {
        if (errno == EINTR) return OkStatus();
        return Error{ErrorCode::kInternal, name_ + ": select: " + strerror(errno)};
    }
    tick();
    if (n == 0) return OkStatus();
    if (FD_ISSET(listen_fd_, &readable)) {
        sockaddr_in peer{};
        socklen_t len = sizeof(peer);
        const int fd = accept(listen_fd_, reinterpret_cast<sockaddr*>(&peer), &len);
        if (fd >= 0) {
            clients_.push_back(fd);
            ++connections_accepted_;
            spdlog::info("{}: client connected from {}:{}", name_, inet_ntoa(peer.sin_addr),
                         ntohs(peer.sin_port));
        }
    }
    uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
    for (std::size_t i = 0; i < clients_.size();) {
        const int fd = clients_[i];
        if (!FD_ISSET(fd, &readable)) {
            ++i;
            continue;
        }
        modbus_set_socket(ctx_, fd);
        const int rc = modbus_receive(ctx_, query);
        if (rc > 0 && handle(ctx_, query, rc)) {
            ++i;
        } else if (rc == 0) {
            ++i;
        } else {
            if (rc < 0) spdlog::info("{}: client disconnected", name_);
            CloseClient(i);
        }
    }
    return OkStatus();
}

Status ModbusServer::ServeRtuOnce(const Handler& handle, const Tick& tick) {
    fd_set readable;
    const int n = WaitReadable({modbus_get_socket(ctx_)}, readable);
    if (n < 0) {
        if (errno == EINTR) return OkStatus();
        return Error{ErrorCode::kInternal, name_ + ": select: " + strerror(errno)};
    }
    tick();
    if (n == 0) return OkStatus();
    uint8_t query[MODBUS_RTU_MAX_ADU_LENGTH];
    const int rc = modbus_receive(ctx_, query);
    if (rc > 0) {
        // On a serial line a "dropped connection" is a reply that never comes.
        handle(ctx_, query, rc);
    } else if (rc < 0) {
        spdlog::debug("{}: bad frame: {}", name_, modbus_strerror(errno));
        modbus_flush(ctx_);
    }
    return OkStatus();
}

}  // namespace boxd
