#pragma once
// AuditTrail: the station's metrological event counter and its events (NIST Handbook 44 G-S.8.2,
// OIML R129, WELMEC guide 7.2's event logger). What bears on a billed figure — the software
// (version, commit, the binary's SHA-256), the calibration in force, and the measurement, scale
// and billing sections of the config — is watched; each change is an event, numbered by a
// counter that only rises, with what changed, from what to what, when and through which
// interface ("config at start", "SIGHUP reload", "POST /v1/calibrate"). Kept in the daemon's
// database (DATA_DIR/boxd.db) beside the records; the first value ever seen of a setting is
// recorded without an event (a new station has changed nothing). Thread-safe.

#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "daemon/service/record_chain.h"
#include "pipeline/core/result.h"
#include "pipeline/io/software_block.h"

struct sqlite3;

namespace YAML {
class Node;
}

namespace boxd {

struct AuditEvent {
    long long counter = 0;  // the event counter after this event
    std::string at;         // UTC timestamp
    std::string what;       // software | calibration | measurement | scale | billing
    std::string from;       // the setting before, as text ("none": absent)
    std::string to;         // the setting after
    std::string via;        // the interface it came through
};

// {"counter", "at", "what", "from", "to", "via"}.
nlohmann::json ToJson(const AuditEvent& event);

// What GET /v1/status, GET /metrics and the page say of the audit trail.
struct AuditStatus {
    long long event_counter = 0;
    std::optional<AuditEvent> last_event;
    SoftwareIdentity software;
    ChainReport chain;             // the stored records' chain, as checked at start
    std::string chain_checked_at;  // UTC timestamp of that check
};

// {"event_counter", "last_event", "software", "records": {"intact", "checked", "unchained",
// "head", "problem", "checked_at"}}.
nlohmann::json ToJson(const AuditStatus& status);

// Returns a config section as canonical text (JSON with sorted keys; "none" when absent): the
// form settings are compared and shown in.
std::string SectionText(const YAML::Node& section);

// Returns up to `limit` events of the trail in `db`, newest first (none in a database without a
// trail).
Result<std::vector<AuditEvent>> ReadAuditEvents(sqlite3* db, int limit);
// Returns the event counter of the trail in `db` (0 without a trail).
Result<long long> ReadEventCounter(sqlite3* db);

class AuditTrail {
public:
    // Returns the trail kept in `data_dir`'s database, or STORAGE_ERROR.
    static Result<std::unique_ptr<AuditTrail>> Open(const std::filesystem::path& data_dir);
    ~AuditTrail();
    AuditTrail(const AuditTrail&) = delete;
    AuditTrail& operator=(const AuditTrail&) = delete;

    // Compares `value`, the current text of setting `what`, with the last one recorded; a change
    // is recorded as an event through `via`. Returns whether it was one.
    Result<bool> Observe(const std::string& what, const std::string& value, const std::string& via);
    // Returns the event counter (0 before any change).
    long long Counter();
    // Returns up to `limit` events, newest first.
    Result<std::vector<AuditEvent>> Events(int limit);

private:
    explicit AuditTrail(sqlite3* db);

    sqlite3* db_;
    std::mutex mutex_;
    long long counter_ = 0;
};

}  // namespace boxd
