#pragma once
// Core: Result<T>: the value of an operation that can fail in an expected way (bad input, a device
// error, "no solution"). Failures carry a stable machine-readable code and a human message.

#include <string>
#include <utility>
#include <variant>

#include "pipeline/core/error_code.h"

namespace boxd {

struct Error {
    ErrorCode code = ErrorCode::kInternal;
    std::string message;  // one line, names the file/field/device concerned
};

template <typename T>
class [[nodiscard]] Result {
public:
    Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
    Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

    bool ok() const { return std::holds_alternative<T>(v_); }
    explicit operator bool() const { return ok(); }

    T& value() & { return std::get<T>(v_); }
    const T& value() const& { return std::get<T>(v_); }
    T&& value() && { return std::get<T>(std::move(v_)); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }

    const Error& error() const { return std::get<Error>(v_); }

private:
    std::variant<T, Error> v_;
};

struct Ok {};
// Status: a Result with no value, for operations that only succeed or fail.
using Status = Result<Ok>;
inline Status OkStatus() { return Ok{}; }

}  // namespace boxd
