#include "pipeline/core/error_code.h"

#include <nlohmann/json.hpp>
#include <ostream>

namespace boxd {

namespace {

struct CodeInfo {
    ErrorCode code;
    const char* name;
    ErrorCategory category;
};

constexpr CodeInfo kCodes[] = {
#define BOXD_ERROR_INFO(e, name, category) {ErrorCode::e, name, ErrorCategory::category},
    BOXD_ERROR_CODES(BOXD_ERROR_INFO)
#undef BOXD_ERROR_INFO
};

const CodeInfo& InfoOf(ErrorCode code) { return kCodes[static_cast<int>(code)]; }

}  // namespace

const char* ErrorCodeName(ErrorCode code) { return InfoOf(code).name; }

std::optional<ErrorCode> ParseErrorCode(std::string_view name) {
    for (const CodeInfo& info : kCodes) {
        if (name == info.name) return info.code;
    }
    return std::nullopt;
}

ErrorCategory CategoryOf(ErrorCode code) { return InfoOf(code).category; }

int HttpStatusOf(ErrorCode code) {
    switch (CategoryOf(code)) {
        case ErrorCategory::kBadInput:
            return 400;
        case ErrorCategory::kUnauthorized:
            return 401;
        case ErrorCategory::kNotFound:
            return 404;
        case ErrorCategory::kMethodNotAllowed:
            return 405;
        case ErrorCategory::kConflict:
            return 409;
        case ErrorCategory::kTooLarge:
            return 413;
        // The request was understood, but its data cannot give what it asked for.
        case ErrorCategory::kNoDimension:
        case ErrorCategory::kCalibrationRefused:
            return 422;
        case ErrorCategory::kUnavailable:
            return 503;
        case ErrorCategory::kDevice:
        case ErrorCategory::kInterrupted:
        case ErrorCategory::kStorage:
        case ErrorCategory::kInternal:
            return 500;
    }
    return 500;
}

int ExitCodeOf(ErrorCode code) {
    switch (CategoryOf(code)) {
        case ErrorCategory::kBadInput:
        case ErrorCategory::kCalibrationRefused:
            return 2;
        case ErrorCategory::kNoDimension:
            return 3;
        default:
            return 1;
    }
}

std::ostream& operator<<(std::ostream& os, ErrorCode code) { return os << ErrorCodeName(code); }

void to_json(nlohmann::json& j, ErrorCode code) { j = ErrorCodeName(code); }

}  // namespace boxd
