#include "daemon/service/record_chain.h"

#include "daemon/service/sha256.h"
#include "daemon/service/sqlite_db.h"

namespace boxd {

const char* const kChainGenesis =
    "0000000000000000000000000000000000000000000000000000000000000000";

std::string ChainHash(const std::string& prev, const std::string& id,
                      const std::string& json_text) {
    return Sha256Hex(prev + "\n" + id + "\n" + json_text);
}

namespace {

bool HasColumn(sqlite3* db, const char* column) {
    SqlStatement q(db, "SELECT 1 FROM pragma_table_info('measurements') WHERE name = ?;");
    if (!q.prepared()) return false;
    q.Bind(1, std::string(column));
    return q.Step() == SQLITE_ROW;
}

}  // namespace

Status AddChainColumns(sqlite3* db) {
    for (const char* column : {"prev_hash", "hash"}) {
        if (HasColumn(db, column)) continue;
        const std::string sql =
            std::string("ALTER TABLE measurements ADD COLUMN ") + column + " TEXT;";
        if (Status s = SqlExec(db, sql.c_str()); !s) return s;
    }
    if (Status s = SqlExec(db,
                           "CREATE TABLE IF NOT EXISTS record_chain ("
                           "  one INTEGER PRIMARY KEY CHECK (one = 1),"
                           "  head_hash TEXT NOT NULL, head_seq INTEGER NOT NULL,"
                           "  pruned_hash TEXT, pruned_seq INTEGER NOT NULL);");
        !s) {
        return s;
    }
    SqlStatement init(db, "INSERT OR IGNORE INTO record_chain VALUES (1, ?, 0, NULL, 0);");
    if (!init.prepared()) return SqlError(db, "cannot prepare the chain's state");
    init.Bind(1, std::string(kChainGenesis));
    if (init.Step() != SQLITE_DONE) return SqlError(db, "cannot start the record chain");
    return OkStatus();
}

Result<std::string> ChainHead(sqlite3* db) {
    SqlStatement q(db, "SELECT head_hash FROM record_chain;");
    if (!q.prepared() || q.Step() != SQLITE_ROW) return SqlError(db, "cannot read the chain head");
    return q.Text(0);
}

Status SetChainHead(sqlite3* db, const std::string& hash, long long seq) {
    SqlStatement u(db, "UPDATE record_chain SET head_hash = ?, head_seq = ?;");
    if (!u.prepared()) return SqlError(db, "cannot prepare the chain head");
    u.Bind(1, hash);
    u.Bind(2, seq);
    if (u.Step() != SQLITE_DONE) return SqlError(db, "cannot move the chain head");
    return OkStatus();
}

Status SetChainPruned(sqlite3* db, const std::string& hash, long long seq) {
    SqlStatement u(db, "UPDATE record_chain SET pruned_hash = ?, pruned_seq = ?;");
    if (!u.prepared()) return SqlError(db, "cannot prepare the chain's pruning");
    u.Bind(1, hash);
    u.Bind(2, seq);
    if (u.Step() != SQLITE_DONE) return SqlError(db, "cannot record the chain's pruning");
    return OkStatus();
}

namespace {

// A data folder from before the chain: its records are counted, unchecked — unless some row
// has a hash, when the chain's state row was removed.
ChainReport WithoutChainState(sqlite3* db) {
    ChainReport r;
    r.head = kChainGenesis;
    SqlStatement n(db, "SELECT count(*) FROM measurements;");
    if (n.prepared() && n.Step() == SQLITE_ROW) r.unchained = n.Int(0);
    if (HasColumn(db, "hash")) {
        SqlStatement h(db, "SELECT count(*) FROM measurements WHERE hash IS NOT NULL;");
        if (h.prepared() && h.Step() == SQLITE_ROW && h.Int(0) > 0) {
            r.intact = false;
            r.problem = "the chain's state was removed from the database";
        }
    }
    return r;
}

Result<ChainReport> VerifyInSnapshot(sqlite3* db) {
    ChainReport r;
    {
        SqlStatement t(db, "SELECT 1 FROM sqlite_master WHERE name = 'record_chain';");
        if (!t.prepared()) return SqlError(db, "cannot read the database's tables");
        if (t.Step() != SQLITE_ROW) return WithoutChainState(db);
    }
    long long head_seq = 0, pruned_seq = 0;
    std::string expected = kChainGenesis;
    {
        SqlStatement q(db,
                       "SELECT head_hash, head_seq, pruned_hash, pruned_seq FROM record_chain;");
        if (!q.prepared() || q.Step() != SQLITE_ROW) {
            return SqlError(db, "cannot read the chain's state");
        }
        r.head = q.Text(0);
        head_seq = q.Int(1);
        if (!q.IsNull(2)) expected = q.Text(2);
        pruned_seq = q.Int(3);
    }
    const auto broken = [&r](const std::string& problem) {
        if (r.intact) r.problem = problem;
        r.intact = false;
    };
    SqlStatement q(db,
                   "SELECT seq, id, result_json, prev_hash, hash FROM measurements"
                   " ORDER BY seq;");
    if (!q.prepared()) return SqlError(db, "cannot read the measurements");
    std::string last_id;
    long long last_seq = pruned_seq;
    int rc;
    while ((rc = q.Step()) == SQLITE_ROW) {
        const std::string id = q.Text(1);
        if (q.IsNull(4)) {
            ++r.unchained;
            if (r.records > 0) broken(id + " has no chain link but follows chained records");
            continue;
        }
        ++r.records;
        if (q.Int(0) <= pruned_seq) broken(id + " is older than what retention removed");
        if (q.Text(3) != expected) {
            broken(last_id.empty()
                       ? id + " does not follow the chain's start: a record before it was deleted"
                       : id + " does not follow " + last_id +
                             ": a record between them was deleted or " + last_id +
                             "'s link was changed");
        }
        const std::string hash = ChainHash(q.Text(3), id, q.Text(2));
        if (hash != q.Text(4)) broken(id + " was changed after it was stored");
        expected = q.Text(4);
        last_id = id;
        last_seq = q.Int(0);
    }
    if (rc != SQLITE_DONE) return SqlError(db, "cannot read the measurements");
    if (r.head != expected || head_seq != last_seq) {
        broken(last_id.empty()
                   ? "the chain's head names records that are not there: they were "
                     "deleted"
                   : "the chain's head is not " + last_id + ": newer records were deleted");
    }
    return r;
}

}  // namespace

Result<ChainReport> VerifyRecordChain(sqlite3* db) {
    // One read transaction: a daemon storing or pruning meanwhile is not seen half-way.
    if (Status s = SqlExec(db, "BEGIN;"); !s) return s.error();
    Result<ChainReport> r = VerifyInSnapshot(db);
    (void)SqlExec(db, "COMMIT;");
    return r;
}

}  // namespace boxd
