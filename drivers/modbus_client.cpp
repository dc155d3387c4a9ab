#include "drivers/modbus_client.h"

#include <modbus/modbus.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <chrono>
#include <thread>

#include "drivers/turntable.h"

namespace boxd {

namespace {

bool IsModbusException(int err) { return err >= EMBXILFUN && err <= EMBXGTAR; }

// "Busy" and "acknowledge" tell the client to ask again later (Modbus Application Protocol
// v1.1b3, section 7); every other exception is the device's final answer.
bool IsRetryableException(int err) { return err == EMBXSBUSY || err == EMBXACK; }

std::string ErrnoText(int err, int timeout_ms) {
    if (err == ETIMEDOUT) return "no reply within " + std::to_string(timeout_ms) + " ms";
    return modbus_strerror(err);
}

std::string RegisterRange(int address, int count) {
    if (count == 1) return "register " + std::to_string(address);
    return "registers " + std::to_string(address) + ".." + std::to_string(address + count - 1);
}

void SetTimeout(modbus_t* ctx, int ms) {
    const auto sec = static_cast<uint32_t>(ms / 1000);
    const auto usec = static_cast<uint32_t>((ms % 1000) * 1000);
    modbus_set_response_timeout(ctx, sec, usec);
    // Gaps inside one reply are bounded by the same figure (RTU replies arrive byte by byte).
    modbus_set_byte_timeout(ctx, sec, usec);
}

}  // namespace

struct ModbusClient::Context {
    modbus_t* ctx = nullptr;
    bool connected = false;
};

ModbusClient::ModbusClient(ModbusLinkConfig config)
    : config_(std::move(config)), ctx_(std::make_unique<Context>()) {}

ModbusClient::~ModbusClient() {
    Close();
    if (ctx_->ctx) modbus_free(ctx_->ctx);
}

std::string ModbusClient::Describe() const {
    if (config_.rtu) {
        return "modbus-rtu " + config_.device + " " + std::to_string(config_.baud) + " " +
               std::to_string(config_.data_bits) + config_.parity +
               std::to_string(config_.stop_bits) + " slave " + std::to_string(config_.slave_id);
    }
    return "modbus-tcp " + config_.host + ":" + std::to_string(config_.port) + " slave " +
           std::to_string(config_.slave_id);
}

Status ModbusClient::Connect() {
    std::string why;
    if (OpenLink(why)) return OkStatus();
    return Error{config_.error_code, Describe() + ": " + why};
}

bool ModbusClient::OpenLink(std::string& why) {
    if (ctx_->connected) return true;
    if (!ctx_->ctx) {
        ctx_->ctx =
            config_.rtu
                ? modbus_new_rtu(config_.device.c_str(), config_.baud, config_.parity,
                                 config_.data_bits, config_.stop_bits)
                : modbus_new_tcp_pi(config_.host.c_str(), std::to_string(config_.port).c_str());
        if (!ctx_->ctx) {
            why = std::string("cannot create the Modbus context: ") + modbus_strerror(errno);
            return false;
        }
        SetTimeout(ctx_->ctx, config_.response_timeout_ms);
        if (modbus_set_slave(ctx_->ctx, config_.slave_id) == -1) {
            why = std::string("invalid slave id: ") + modbus_strerror(errno);
            modbus_free(ctx_->ctx);
            ctx_->ctx = nullptr;
            return false;
        }
    }
    if (modbus_connect(ctx_->ctx) == -1) {
        why = "cannot connect: " + ErrnoText(errno, config_.response_timeout_ms);
        return false;
    }
    // A serial line may still hold bytes of a reply that came too late for an earlier request.
    if (config_.rtu) modbus_flush(ctx_->ctx);
    ctx_->connected = true;
    ++connections_opened_;
    if (connections_opened_ > 1) spdlog::info("{}: reconnected", Describe());
    return true;
}

void ModbusClient::Close() {
    if (ctx_->ctx && ctx_->connected) modbus_close(ctx_->ctx);
    ctx_->connected = false;
}

template <typename Fn>
Status ModbusClient::Transact(const std::string& what, Fn&& fn) {
    const int attempts = config_.retries + 1;
    std::string last_error;
    for (int attempt = 0; attempt < attempts; ++attempt) {
        if (attempt > 0) {
            spdlog::debug("{}: {} failed ({}), retrying", Describe(), what, last_error);
            std::this_thread::sleep_for(std::chrono::milliseconds(config_.retry_delay_ms));
        }
        if (!OpenLink(last_error)) continue;
        errno = 0;
        if (fn(ctx_->ctx) != -1) return OkStatus();
        const int err = errno;
        if (IsModbusException(err)) {
            if (IsRetryableException(err)) {
                last_error = std::string("Modbus exception: ") + modbus_strerror(err);
                continue;
            }
            return Error{config_.error_code, Describe() + ": " + what +
                                                 ": the device answered with a Modbus exception: " +
                                                 modbus_strerror(err)};
        }
        // Transport failure: the connection may be dead or hold a late reply; start afresh.
        last_error = ErrnoText(err, config_.response_timeout_ms);
        Close();
    }
    return Error{config_.error_code,
                 Describe() + ": " + what + " failed after " + std::to_string(attempts) +
                     (attempts == 1 ? " attempt: " : " attempts: ") + last_error};
}

Result<std::vector<uint16_t>> ModbusClient::ReadRegisters(int address, int count,
                                                          const std::string& label) {
    std::vector<uint16_t> values(static_cast<std::size_t>(count));
    const std::string what =
        "reading " + (label.empty() ? "" : label + ", ") + RegisterRange(address, count);
    auto st = Transact(what, [&](modbus_t* ctx) {
        const int n = modbus_read_registers(ctx, address, count, values.data());
        if (n != -1 && n != count) {
            errno = EMBBADDATA;
            return -1;
        }
        return n;
    });
    if (!st) return st.error();
    return values;
}

Status ModbusClient::WriteRegisters(int address, const std::vector<uint16_t>& values,
                                    const std::string& label) {
    const int count = static_cast<int>(values.size());
    const std::string what =
        "writing " + (label.empty() ? "" : label + ", ") + RegisterRange(address, count);
    return Transact(what, [&](modbus_t* ctx) {
        return modbus_write_registers(ctx, address, count, values.data());
    });
}

}  // namespace boxd
