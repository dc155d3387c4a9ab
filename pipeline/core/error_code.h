#pragma once
// Core: ErrorCode: every error and refusal code boxd reports, each with one category. The category,
// never the code, decides the HTTP status (HttpStatusOf) and the exit code (ExitCodeOf), so a new
// code cannot silently become a 500. The codes' names are what the JSON carries (SPEC sections 5
// and 6): stable, upper snake case.

#include <iosfwd>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string_view>

namespace boxd {

enum class ErrorCategory {
    kBadInput,            // the caller's input or configuration is invalid: 400, exit 2
    kUnauthorized,        // a request without a valid token: 401
    kNotFound,            // no such route, measurement or file: 404
    kMethodNotAllowed,    // a known path asked with a method it does not serve: 405
    kConflict,            // the station is busy: 409
    kTooLarge,            // a request body over the limit: 413
    kNoDimension,         // measured, but no size the data supports (status no_dim): 422, exit 3
    kCalibrationRefused,  // the session cannot calibrate the station: 422, exit 2
    kDevice,              // the turntable or the camera failed: 500, exit 1
    kInterrupted,         // a run was cancelled or aborted (shutdown): 500, exit 1
    kUnavailable,         // the service cannot answer now (stopping, stalled, still running): 503
    kStorage,             // the data folder or a file could not be written or read: 500, exit 1
    kInternal,            // a defect or an environment failure: 500, exit 1
};

// X(enumerator, JSON name, category): the one list of codes.
#define BOXD_ERROR_CODES(X)                                       \
    X(kInvalidInput, "INVALID_INPUT", kBadInput)                  \
    X(kInvalidConfig, "INVALID_CONFIG", kBadInput)                \
    X(kInvalidSession, "INVALID_SESSION", kBadInput)              \
    X(kBadRequest, "BAD_REQUEST", kBadInput)                      \
    X(kUnauthorized, "UNAUTHORIZED", kUnauthorized)               \
    X(kNotFound, "NOT_FOUND", kNotFound)                          \
    X(kMethodNotAllowed, "METHOD_NOT_ALLOWED", kMethodNotAllowed) \
    X(kBusy, "BUSY", kConflict)                                   \
    X(kPayloadTooLarge, "PAYLOAD_TOO_LARGE", kTooLarge)           \
    X(kNoObject, "NO_OBJECT", kNoDimension)                       \
    X(kObjectTooSmall, "OBJECT_TOO_SMALL", kNoDimension)          \
    X(kObjectTooLarge, "OBJECT_TOO_LARGE", kNoDimension)          \
    X(kRegistrationFailed, "REGISTRATION_FAILED", kNoDimension)   \
    X(kObjectMoved, "OBJECT_MOVED", kNoDimension)                 \
    X(kInsufficientData, "INSUFFICIENT_DATA", kNoDimension)       \
    X(kMultipleObjects, "MULTIPLE_OBJECTS", kNoDimension)         \
    X(kUncertain, "UNCERTAIN", kNoDimension)                      \
    X(kNotCalibrated, "NOT_CALIBRATED", kNoDimension)             \
    X(kTooFewPoses, "TOO_FEW_POSES", kCalibrationRefused)         \
    X(kTableNotVisible, "TABLE_NOT_VISIBLE", kCalibrationRefused) \
    X(kNoReference, "NO_REFERENCE", kCalibrationRefused)          \
    X(kWrongReference, "WRONG_REFERENCE", kCalibrationRefused)    \
    X(kBoxMoved, "BOX_MOVED", kCalibrationRefused)                \
    X(kNotConverged, "NOT_CONVERGED", kCalibrationRefused)        \
    X(kCameraError, "CAMERA_ERROR", kDevice)                      \
    X(kTurntableError, "TURNTABLE_ERROR", kDevice)                \
    X(kScaleError, "SCALE_ERROR", kDevice)                        \
    X(kCancelled, "CANCELLED", kInterrupted)                      \
    X(kAborted, "ABORTED", kInterrupted)                          \
    X(kShuttingDown, "SHUTTING_DOWN", kUnavailable)               \
    X(kTimeout, "TIMEOUT", kUnavailable)                          \
    X(kLoopStalled, "LOOP_STALLED", kUnavailable)                 \
    X(kStorageError, "STORAGE_ERROR", kStorage)                   \
    X(kIoError, "IO_ERROR", kStorage)                             \
    X(kBindFailed, "BIND_FAILED", kInternal)                      \
    X(kInternal, "INTERNAL_ERROR", kInternal)

enum class ErrorCode {
#define BOXD_ERROR_ENUMERATOR(e, name, category) e,
    BOXD_ERROR_CODES(BOXD_ERROR_ENUMERATOR)
#undef BOXD_ERROR_ENUMERATOR
};

// Returns the code's JSON name ("NO_OBJECT").
const char* ErrorCodeName(ErrorCode code);

// Returns the code whose JSON name is `name`, or nullopt.
std::optional<ErrorCode> ParseErrorCode(std::string_view name);

// Returns the code's category.
ErrorCategory CategoryOf(ErrorCode code);

// Returns the HTTP status of an error of `code` (SPEC section 6).
int HttpStatusOf(ErrorCode code);

// Returns the exit code of a command that ends on an error of `code` (SPEC section 4).
int ExitCodeOf(ErrorCode code);

// Prints the JSON name (test failure messages, logs).
std::ostream& operator<<(std::ostream& os, ErrorCode code);

// Writes the JSON name: a code never reaches JSON as a number.
void to_json(nlohmann::json& j, ErrorCode code);

}  // namespace boxd
