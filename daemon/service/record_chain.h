#pragma once
// The hash chain over the stored measurements (WELMEC guide 7.2's protection of stored data):
// each record's row carries the hash of the record before it and its own,
//   hash = SHA-256(previous hash "\n" id "\n" stored JSON),
// and the chain's state row keeps the head (the newest record's hash) and, once the retention
// limit has removed records, the hash of the newest removed one. A record edited, inserted or
// deleted with a database tool breaks a link, the head, or the link to what retention removed:
// VerifyRecordChain finds it and names the record. It is a check against changes by hand, not a
// signature: someone who recomputes every later hash and the head as well is not detected —
// the head /v1/status publishes (audit.records.head) is what a fleet can hold it to.
// Records stored before the chain existed (an older data folder) are counted, not checked.

#include <string>

#include "pipeline/core/result.h"

struct sqlite3;

namespace boxd {

// The previous hash of the first record ever stored: 64 zeros.
extern const char* const kChainGenesis;

// Returns SHA-256(prev "\n" id "\n" json_text) in hex.
std::string ChainHash(const std::string& prev, const std::string& id, const std::string& json_text);

// Adds the chain's columns (prev_hash, hash) to the measurements table and its state row, when
// the database predates them.
Status AddChainColumns(sqlite3* db);

// Returns the chain's head (the newest record's hash, or the genesis); in the caller's
// transaction.
Result<std::string> ChainHead(sqlite3* db);
// Makes `hash` (of record `seq`) the head; in the caller's transaction.
Status SetChainHead(sqlite3* db, const std::string& hash, long long seq);
// Records that retention removes every record up to `seq`, the newest of them hashed `hash`;
// in the caller's transaction, before the rows go.
Status SetChainPruned(sqlite3* db, const std::string& hash, long long seq);

struct ChainReport {
    bool intact = true;
    long long records = 0;    // records checked
    long long unchained = 0;  // records from before the chain (not checked)
    std::string head;         // the head the state row holds
    std::string problem;      // the first break found, naming the record
};

// Checks every stored record against the chain, oldest first.
Result<ChainReport> VerifyRecordChain(sqlite3* db);

}  // namespace boxd
