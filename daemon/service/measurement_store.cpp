#include "daemon/service/measurement_store.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>

#include "daemon/service/record_chain.h"
#include "daemon/service/sqlite_db.h"
#include "pipeline/core/json_text.h"

namespace boxd {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

Error StorageError(const std::string& what) { return Error{ErrorCode::kStorageError, what}; }

// Ids are "m-" and six to twelve digits; anything else never reaches SQL or the file system.
// A test of the characters, not a function-local regular expression: that is destroyed at exit,
// while a server thread may still be answering a request that reads it.
bool IsValidId(const std::string& id) {
    if (id.size() < 8 || id.size() > 14 || id.compare(0, 2, "m-") != 0) return false;
    return std::all_of(id.begin() + 2, id.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Moves `from` to `to` (same file system: an atomic rename; otherwise copy then remove).
Status MoveInto(const fs::path& from, const fs::path& to) {
    std::error_code ec;
    fs::remove_all(to, ec);
    fs::rename(from, to, ec);
    if (!ec) return OkStatus();
    fs::copy(from, to, fs::copy_options::recursive, ec);
    if (ec)
        return StorageError("cannot move " + from.string() + " to " + to.string() + ": " +
                            ec.message());
    fs::remove_all(from, ec);
    return OkStatus();
}

// Databases written before parcel ids lack the column: it is added (NULL for their rows).
Status AddParcelIdColumn(sqlite3* db) {
    bool present = false;
    {
        SqlStatement q(db,
                       "SELECT 1 FROM pragma_table_info('measurements')"
                       " WHERE name = 'parcel_id';");
        if (!q.prepared()) return SqlError(db, "cannot read the measurements table's columns");
        present = q.Step() == SQLITE_ROW;
    }
    auto exec = [db](const char* sql) {
        SqlStatement s(db, sql);
        return s.prepared() && s.Step() == SQLITE_DONE;
    };
    if (!present && !exec("ALTER TABLE measurements ADD COLUMN parcel_id TEXT;")) {
        return SqlError(db, "cannot add the parcel_id column");
    }
    if (!exec("CREATE INDEX IF NOT EXISTS measurements_by_parcel ON measurements (parcel_id, "
              "seq);")) {
        return SqlError(db, "cannot index the parcel ids");
    }
    return OkStatus();
}

Result<std::optional<json>> ParseStored(const std::string& text, const std::string& id) {
    json j = json::parse(text, nullptr, false);
    if (j.is_discarded()) return StorageError("stored JSON of " + id + " is corrupt");
    return std::optional<json>(std::move(j));
}

// The stored measurements (id, result_json) the query `q` on `db` gives, in its order.
Result<std::vector<json>> StoredRows(sqlite3* db, SqlStatement& q) {
    std::vector<json> out;
    int rc;
    while ((rc = q.Step()) == SQLITE_ROW) {
        auto j = ParseStored(q.Text(1), q.Text(0));
        if (!j) return j.error();
        out.push_back(std::move(**j));
    }
    if (rc != SQLITE_DONE) return SqlError(db, "cannot list measurements");
    return out;
}

// A record retention removes, and its files.
struct Doomed {
    std::string id, cloud_file, session_dir, hash;
};

// Inserts `result`'s row linked to the chain's head and makes it the head; in a transaction.
Status InsertChained(sqlite3* db, const MeasurementResult& result, long long seq,
                     const std::optional<std::string>& cloud_file,
                     const std::optional<std::string>& session_dir) {
    const std::string& id = result.id;
    const std::string text = JsonText(ToJson(result));
    auto prev = ChainHead(db);
    if (!prev) return prev.error();
    const std::string hash = ChainHash(*prev, id, text);
    SqlStatement insert(db,
                        "INSERT INTO measurements (seq, id, started_at, finished_at, status,"
                        " result_json, cloud_file, session_dir, parcel_id, prev_hash, hash)"
                        " VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?);");
    if (!insert.prepared()) return SqlError(db, "cannot prepare the insert");
    insert.Bind(1, seq);
    insert.Bind(2, id);
    insert.Bind(3, result.started_at);
    insert.Bind(4, result.finished_at);
    insert.Bind(5, std::string(StatusName(result.status)));
    insert.Bind(6, text);
    cloud_file ? insert.Bind(7, *cloud_file) : insert.BindNull(7);
    session_dir ? insert.Bind(8, *session_dir) : insert.BindNull(8);
    result.parcel_id ? insert.Bind(9, *result.parcel_id) : insert.BindNull(9);
    insert.Bind(10, *prev);
    insert.Bind(11, hash);
    if (insert.Step() != SQLITE_DONE) return SqlError(db, "cannot store " + id);
    return SetChainHead(db, hash, seq);
}

// Deletes the rows beyond the newest `retention` (listing them in `doomed`) and records the
// newest removed record's hash for the chain; in a transaction.
Status PruneRows(sqlite3* db, int retention, std::vector<Doomed>& doomed) {
    long long newest_seq = 0;
    {
        SqlStatement q(db,
                       "SELECT id, cloud_file, session_dir, hash, seq FROM measurements"
                       " ORDER BY seq DESC LIMIT -1 OFFSET ?;");
        if (!q.prepared()) return SqlError(db, "cannot prepare the retention query");
        q.Bind(1, static_cast<long long>(retention));
        int rc;
        while ((rc = q.Step()) == SQLITE_ROW) {
            if (doomed.empty()) newest_seq = q.Int(4);
            doomed.push_back({q.Text(0), q.Text(1), q.Text(2), q.Text(3)});
        }
        if (rc != SQLITE_DONE) return SqlError(db, "cannot list what retention removes");
    }
    if (doomed.empty()) return OkStatus();
    if (!doomed.front().hash.empty()) {
        if (Status s = SetChainPruned(db, doomed.front().hash, newest_seq); !s) return s;
    }
    SqlStatement del(db, "DELETE FROM measurements WHERE seq <= ?;");
    if (!del.prepared()) return SqlError(db, "cannot prepare the retention delete");
    del.Bind(1, newest_seq);
    if (del.Step() != SQLITE_DONE) return SqlError(db, "cannot apply the retention limit");
    return OkStatus();
}

}  // namespace

MeasurementStore::MeasurementStore(fs::path data_dir, sqlite3* db, int retention)
    : data_dir_(std::move(data_dir)), db_(db), retention_(retention) {}

MeasurementStore::~MeasurementStore() { sqlite3_close(db_); }

Result<std::unique_ptr<MeasurementStore>> MeasurementStore::Open(const fs::path& data_dir,
                                                                 int retention) {
    std::error_code ec;
    for (const char* sub : {"clouds", "sessions", "tmp"}) {
        fs::create_directories(data_dir / sub, ec);
        if (ec) {
            return StorageError("cannot create " + (data_dir / sub).string() + ": " + ec.message());
        }
    }
    // Scratch folders of measurements that never finished (crash, kill -9) are garbage.
    for (const auto& entry : fs::directory_iterator(data_dir / "tmp", ec)) {
        std::error_code rm;
        fs::remove_all(entry.path(), rm);
    }

    auto db = OpenDatabase(data_dir, {
                                         "CREATE TABLE IF NOT EXISTS measurements ("
                                         "  seq INTEGER PRIMARY KEY,"
                                         "  id TEXT NOT NULL UNIQUE,"
                                         "  started_at TEXT NOT NULL,"
                                         "  finished_at TEXT NOT NULL,"
                                         "  status TEXT NOT NULL,"
                                         "  result_json TEXT NOT NULL,"
                                         "  cloud_file TEXT,"
                                         "  session_dir TEXT);",
                                         "CREATE TABLE IF NOT EXISTS id_counter ("
                                         "  one INTEGER PRIMARY KEY CHECK (one = 1),"
                                         "  last_seq INTEGER NOT NULL);",
                                         "INSERT OR IGNORE INTO id_counter VALUES (1, 0);",
                                     });
    if (!db) return db.error();
    for (Status s : {AddParcelIdColumn(*db), AddChainColumns(*db)}) {
        if (!s) {
            sqlite3_close(*db);
            return s.error();
        }
    }
    std::unique_ptr<MeasurementStore> store(new MeasurementStore(data_dir, *db, retention));
    return store;
}

void MeasurementStore::set_retention(int retention) {
    std::lock_guard lock(mutex_);
    retention_ = retention;
}

Result<std::string> MeasurementStore::ReserveId() {
    std::lock_guard lock(mutex_);
    if (auto s = SqlExec(db_, "BEGIN IMMEDIATE;"); !s) return s.error();
    // The counter never goes below the largest stored id, even if the counter row was lost.
    if (auto s = SqlExec(db_,
                         "UPDATE id_counter SET last_seq = 1 + max(last_seq,"
                         " (SELECT coalesce(max(seq), 0) FROM measurements));");
        !s) {
        (void)SqlExec(db_, "ROLLBACK;");
        return s.error();
    }
    SqlStatement q(db_, "SELECT last_seq FROM id_counter;");
    if (!q.prepared() || q.Step() != SQLITE_ROW) {
        Error e = SqlError(db_, "cannot read the id counter");
        (void)SqlExec(db_, "ROLLBACK;");
        return e;
    }
    const long long seq = q.Int(0);
    if (auto s = SqlExec(db_, "COMMIT;"); !s) return s.error();
    char id[32];
    std::snprintf(id, sizeof(id), "m-%06lld", seq);
    return std::string(id);
}

Result<fs::path> MeasurementStore::MakeScratchDir(const std::string& id) {
    if (!IsValidId(id)) return StorageError("invalid measurement id '" + id + "'");
    const fs::path dir = data_dir_ / "tmp" / id;
    std::error_code ec;
    fs::remove_all(dir, ec);
    fs::create_directories(dir, ec);
    if (ec) return StorageError("cannot create " + dir.string() + ": " + ec.message());
    return dir;
}

void MeasurementStore::RemoveScratchDir(const std::string& id) {
    if (!IsValidId(id)) return;
    std::error_code ec;
    fs::remove_all(data_dir_ / "tmp" / id, ec);
}

Status MeasurementStore::Save(const MeasurementResult& result, const MeasurementFiles& files) {
    const std::string& id = result.id;
    if (!IsValidId(id)) return StorageError("cannot store a measurement with id '" + id + "'");
    const long long seq = std::stoll(id.substr(2));
    std::lock_guard lock(mutex_);

    std::optional<std::string> cloud_file, session_dir;
    if (files.cloud_ply) {
        cloud_file = "clouds/" + id + ".ply";
        if (auto s = MoveInto(*files.cloud_ply, data_dir_ / *cloud_file); !s) return s;
    }
    if (files.session_dir) {
        session_dir = "sessions/" + id;
        if (auto s = MoveInto(*files.session_dir, data_dir_ / *session_dir); !s) return s;
    }

    // The row, its link in the chain and what retention removes commit together.
    if (auto s = SqlExec(db_, "BEGIN IMMEDIATE;"); !s) return s;
    std::vector<Doomed> doomed;
    Status stored = InsertChained(db_, result, seq, cloud_file, session_dir);
    if (stored) stored = PruneRows(db_, retention_, doomed);
    if (stored) stored = SqlExec(db_, "COMMIT;");
    if (!stored) {
        (void)SqlExec(db_, "ROLLBACK;");
        return stored;
    }
    // Rows go first: a file without a row is harmless, a row without its file is not.
    for (const auto& d : doomed) {
        std::error_code ec;
        if (!d.cloud_file.empty()) fs::remove(data_dir_ / d.cloud_file, ec);
        if (!d.session_dir.empty()) fs::remove_all(data_dir_ / d.session_dir, ec);
        spdlog::debug("retention: removed measurement {}", d.id);
    }
    return OkStatus();
}

Result<ChainReport> MeasurementStore::VerifyChain() {
    std::lock_guard lock(mutex_);
    return VerifyRecordChain(db_);
}

Result<std::string> MeasurementStore::ChainHeadHash() {
    std::lock_guard lock(mutex_);
    return ChainHead(db_);
}

Result<std::optional<json>> MeasurementStore::Last() {
    std::lock_guard lock(mutex_);
    SqlStatement q(db_, "SELECT id, result_json FROM measurements ORDER BY seq DESC LIMIT 1;");
    if (!q.prepared()) return SqlError(db_, "cannot prepare a query");
    const int rc = q.Step();
    if (rc == SQLITE_DONE) return std::optional<json>();
    if (rc != SQLITE_ROW) return SqlError(db_, "cannot read the last measurement");
    return ParseStored(q.Text(1), q.Text(0));
}

Result<std::optional<json>> MeasurementStore::Get(const std::string& id) {
    if (!IsValidId(id)) return std::optional<json>();
    std::lock_guard lock(mutex_);
    SqlStatement q(db_, "SELECT result_json FROM measurements WHERE id = ?;");
    if (!q.prepared()) return SqlError(db_, "cannot prepare a query");
    q.Bind(1, id);
    const int rc = q.Step();
    if (rc == SQLITE_DONE) return std::optional<json>();
    if (rc != SQLITE_ROW) return SqlError(db_, "cannot read measurement " + id);
    return ParseStored(q.Text(0), id);
}

Result<std::vector<json>> MeasurementStore::List(int limit,
                                                 const std::optional<std::string>& parcel_id) {
    std::lock_guard lock(mutex_);
    SqlStatement q(db_, parcel_id ? "SELECT id, result_json FROM measurements WHERE parcel_id = ?"
                                    " ORDER BY seq DESC LIMIT ?;"
                                  : "SELECT id, result_json FROM measurements"
                                    " ORDER BY seq DESC LIMIT ?;");
    if (!q.prepared()) return SqlError(db_, "cannot prepare a query");
    int param = 1;
    if (parcel_id) q.Bind(param++, *parcel_id);
    q.Bind(param, static_cast<long long>(limit));
    return StoredRows(db_, q);
}

Result<std::vector<json>> ReadMeasurementsSince(sqlite3* db, const std::string& since) {
    SqlStatement q(db,
                   "SELECT id, result_json FROM measurements WHERE finished_at >= ?"
                   " ORDER BY seq;");
    if (!q.prepared()) return SqlError(db, "cannot prepare a query");
    q.Bind(1, since);
    return StoredRows(db, q);
}

Result<std::vector<json>> MeasurementStore::ListSince(const std::string& since) {
    std::lock_guard lock(mutex_);
    return ReadMeasurementsSince(db_, since);
}

Result<std::optional<fs::path>> MeasurementStore::CloudPath(const std::string& id) {
    if (!IsValidId(id)) return std::optional<fs::path>();
    std::lock_guard lock(mutex_);
    SqlStatement q(db_, "SELECT cloud_file FROM measurements WHERE id = ?;");
    if (!q.prepared()) return SqlError(db_, "cannot prepare a query");
    q.Bind(1, id);
    const int rc = q.Step();
    if (rc == SQLITE_DONE || (rc == SQLITE_ROW && q.IsNull(0))) return std::optional<fs::path>();
    if (rc != SQLITE_ROW) return SqlError(db_, "cannot read measurement " + id);
    return std::optional<fs::path>(data_dir_ / q.Text(0));
}

Result<int> MeasurementStore::Count() {
    std::lock_guard lock(mutex_);
    SqlStatement q(db_, "SELECT count(*) FROM measurements;");
    if (!q.prepared() || q.Step() != SQLITE_ROW) return SqlError(db_, "cannot count");
    return static_cast<int>(q.Int(0));
}

}  // namespace boxd
