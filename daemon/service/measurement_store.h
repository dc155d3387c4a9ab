#pragma once
// MeasurementStore: the durable record of finished measurements. One SQLite database in WAL mode
// (data_dir/boxd.db) holds every finished measurement's JSON, read back as stored (the API serves
// it as is); fused clouds live beside it as PLY files (data_dir/clouds/<id>.ply) and, optionally,
// captured sessions (data_dir/sessions/<id>/). A row is committed only after its files are in
// place, so what the database lists is always servable, also after a crash or kill -9. Every row
// is a link of a hash chain (record_chain.h) that finds a record changed by hand. Thread-safe.

#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "daemon/service/record_chain.h"
#include "pipeline/core/result.h"
#include "pipeline/io/measurement.h"

struct sqlite3;

namespace boxd {

// Files a finished measurement left in its scratch folder, moved into the store by Save().
struct MeasurementFiles {
    std::optional<std::filesystem::path> cloud_ply;
    std::optional<std::filesystem::path> session_dir;
};

// ListSince on a database opened elsewhere (`boxd export`, read-only).
Result<std::vector<nlohmann::json>> ReadMeasurementsSince(sqlite3* db, const std::string& since);

class MeasurementStore {
public:
    // Returns the store in `data_dir` (created when missing), keeping at most `retention`
    // measurements, or STORAGE_ERROR. Leftover scratch folders of an interrupted run are removed.
    static Result<std::unique_ptr<MeasurementStore>> Open(const std::filesystem::path& data_dir,
                                                          int retention);
    ~MeasurementStore();
    MeasurementStore(const MeasurementStore&) = delete;
    MeasurementStore& operator=(const MeasurementStore&) = delete;

    const std::filesystem::path& data_dir() const { return data_dir_; }
    void set_retention(int retention);

    // Returns a new id "m-000042", never handed out before in this data folder (the counter is
    // committed before the id is returned, so a crash mid-measurement does not reuse it).
    Result<std::string> ReserveId();
    // Returns a fresh, empty scratch folder for measurement `id` (data_dir/tmp/<id>).
    Result<std::filesystem::path> MakeScratchDir(const std::string& id);
    // Removes the scratch folder of `id` (after Save, or when a run is abandoned).
    void RemoveScratchDir(const std::string& id);

    // Stores the finished measurement `result` (its id names it) as its SPEC section 5 JSON
    // (ToJson): moves `files` into the store, commits the row, then applies the retention limit.
    Status Save(const MeasurementResult& result, const MeasurementFiles& files);

    // Returns the most recently finished measurement, or nullopt when there is none.
    Result<std::optional<nlohmann::json>> Last();
    // Returns measurement `id`, or nullopt when it is not stored.
    Result<std::optional<nlohmann::json>> Get(const std::string& id);
    // Returns up to `limit` measurements, newest first; with `parcel_id`, only that parcel's.
    Result<std::vector<nlohmann::json>> List(int limit,
                                             const std::optional<std::string>& parcel_id = {});
    // Returns every measurement finished at or after `since` (CheckSince's form; "" for all),
    // oldest first.
    Result<std::vector<nlohmann::json>> ListSince(const std::string& since);
    // Returns the path of the fused cloud of `id`, or nullopt when `id` or its cloud is missing.
    Result<std::optional<std::filesystem::path>> CloudPath(const std::string& id);
    // Returns the number of stored measurements.
    Result<int> Count();
    // Checks the stored records against their hash chain (daemon/service/record_chain.h).
    Result<ChainReport> VerifyChain();
    // Returns the chain's head: the newest record's hash.
    Result<std::string> ChainHeadHash();

private:
    MeasurementStore(std::filesystem::path data_dir, sqlite3* db, int retention);

    std::filesystem::path data_dir_;
    sqlite3* db_ = nullptr;
    int retention_ = 0;
    std::mutex mutex_;
};

}  // namespace boxd
