#include "daemon/service/audit_trail.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <nlohmann/json.hpp>

#include "daemon/service/sqlite_db.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/measurement.h"

namespace boxd {

namespace {

using nlohmann::json;

json YamlToJson(const YAML::Node& node) {
    if (node.IsMap()) {
        json out = json::object();
        for (const auto& kv : node) out[kv.first.Scalar()] = YamlToJson(kv.second);
        return out;
    }
    if (node.IsSequence()) {
        json out = json::array();
        for (const auto& item : node) out.push_back(YamlToJson(item));
        return out;
    }
    if (node.IsScalar()) return node.Scalar();
    return nullptr;
}

}  // namespace

json ToJson(const AuditEvent& e) {
    return {{"counter", e.counter}, {"at", e.at}, {"what", e.what},
            {"from", e.from},       {"to", e.to}, {"via", e.via}};
}

json ToJson(const AuditStatus& a) {
    return {{"event_counter", a.event_counter},
            {"last_event", a.last_event ? ToJson(*a.last_event) : json(nullptr)},
            {"software", ToJson(a.software)},
            {"records",
             {{"intact", a.chain.intact},
              {"checked", a.chain.records},
              {"unchained", a.chain.unchained},
              {"head", a.chain.head},
              {"problem", a.chain.problem.empty() ? json(nullptr) : json(a.chain.problem)},
              {"checked_at", a.chain_checked_at}}}};
}

std::string SectionText(const YAML::Node& section) {
    if (!section || section.IsNull()) return "none";
    return JsonText(YamlToJson(section));
}

AuditTrail::AuditTrail(sqlite3* db) : db_(db) {}

AuditTrail::~AuditTrail() { sqlite3_close(db_); }

Result<std::unique_ptr<AuditTrail>> AuditTrail::Open(const std::filesystem::path& data_dir) {
    auto db = OpenDatabase(data_dir, {
                                         "CREATE TABLE IF NOT EXISTS audit_events ("
                                         "  counter INTEGER PRIMARY KEY,"
                                         "  at TEXT NOT NULL, what TEXT NOT NULL,"
                                         "  from_value TEXT NOT NULL, to_value TEXT NOT NULL,"
                                         "  via TEXT NOT NULL);",
                                         "CREATE TABLE IF NOT EXISTS audit_settings ("
                                         "  what TEXT PRIMARY KEY, value TEXT NOT NULL);",
                                     });
    if (!db) return db.error();
    std::unique_ptr<AuditTrail> trail(new AuditTrail(*db));
    std::lock_guard lock(trail->mutex_);
    auto counter = ReadEventCounter(trail->db_);
    if (!counter) return counter.error();
    trail->counter_ = *counter;
    return trail;
}

namespace {

bool HasTrail(sqlite3* db) {
    SqlStatement t(db, "SELECT 1 FROM sqlite_master WHERE name = 'audit_events';");
    return t.prepared() && t.Step() == SQLITE_ROW;
}

}  // namespace

Result<long long> ReadEventCounter(sqlite3* db) {
    if (!HasTrail(db)) return 0LL;
    SqlStatement q(db, "SELECT coalesce(max(counter), 0) FROM audit_events;");
    if (!q.prepared() || q.Step() != SQLITE_ROW) {
        return SqlError(db, "cannot read the event counter");
    }
    return q.Int(0);
}

Result<bool> AuditTrail::Observe(const std::string& what, const std::string& value,
                                 const std::string& via) {
    std::lock_guard lock(mutex_);
    std::optional<std::string> before;
    {
        SqlStatement q(db_, "SELECT value FROM audit_settings WHERE what = ?;");
        if (!q.prepared()) return SqlError(db_, "cannot read the audited settings");
        q.Bind(1, what);
        if (q.Step() == SQLITE_ROW) before = q.Text(0);
    }
    if (before && *before == value) return false;
    if (auto s = SqlExec(db_, "BEGIN IMMEDIATE;"); !s) return s.error();
    const auto fail = [this](const std::string& doing) {
        Error e = SqlError(db_, doing);
        (void)SqlExec(db_, "ROLLBACK;");
        return e;
    };
    SqlStatement set(db_, "INSERT OR REPLACE INTO audit_settings VALUES (?, ?);");
    set.Bind(1, what);
    set.Bind(2, value);
    if (!set.prepared() || set.Step() != SQLITE_DONE) return fail("cannot record " + what);
    AuditEvent e{0, UtcTimestampNow(), what, before.value_or(""), value, via};
    if (before) {
        auto counter = ReadEventCounter(db_);
        if (!counter) return fail("cannot read the event counter");
        e.counter = *counter + 1;
        SqlStatement add(db_, "INSERT INTO audit_events VALUES (?, ?, ?, ?, ?, ?);");
        add.Bind(1, e.counter);
        add.Bind(2, e.at);
        add.Bind(3, e.what);
        add.Bind(4, e.from);
        add.Bind(5, e.to);
        add.Bind(6, e.via);
        if (!add.prepared() || add.Step() != SQLITE_DONE) return fail("cannot record the event");
    }
    if (auto s = SqlExec(db_, "COMMIT;"); !s) return fail("cannot commit the event");
    if (!before) return false;
    counter_ = e.counter;
    spdlog::warn("metrological event {}: {} changed through {}: {} -> {}", e.counter, what, via,
                 e.from, e.to);
    return true;
}

long long AuditTrail::Counter() {
    std::lock_guard lock(mutex_);
    return counter_;
}

Result<std::vector<AuditEvent>> AuditTrail::Events(int limit) {
    std::lock_guard lock(mutex_);
    return ReadAuditEvents(db_, limit);
}

Result<std::vector<AuditEvent>> ReadAuditEvents(sqlite3* db, int limit) {
    std::vector<AuditEvent> out;
    if (!HasTrail(db)) return out;
    SqlStatement q(db,
                   "SELECT counter, at, what, from_value, to_value, via FROM audit_events"
                   " ORDER BY counter DESC LIMIT ?;");
    if (!q.prepared()) return SqlError(db, "cannot read the events");
    q.Bind(1, static_cast<long long>(limit));
    while (q.Step() == SQLITE_ROW) {
        out.push_back({q.Int(0), q.Text(1), q.Text(2), q.Text(3), q.Text(4), q.Text(5)});
    }
    return out;
}

}  // namespace boxd
