// `boxd export --data-dir DIR [--since T]`: the stored measurements as CSV on stdout, as GET
// /v1/measurements.csv gives them — read-only, beside a running daemon too.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>

#include "daemon/cli/cli.h"
#include "daemon/service/measurement_csv.h"
#include "daemon/service/measurement_store.h"
#include "daemon/service/sqlite_db.h"

namespace boxd::cli {

namespace {

struct ExportOptions {
    std::string data_dir;
    std::string since;
};

int RunExport(const ExportOptions& o) {
    std::string since;
    if (!o.since.empty()) {
        auto checked = CheckSince(o.since);
        if (!checked) return Fail(Error{ErrorCode::kInvalidInput, "--" + checked.error().message});
        since = *checked;
    }
    auto opened = OpenDatabaseReadOnly(o.data_dir);
    if (!opened) {
        return Fail(Error{ErrorCode::kInvalidInput, "--data-dir: " + opened.error().message});
    }
    const DatabaseHandle db = std::move(*opened);
    auto records = ReadMeasurementsSince(db.get(), since);
    if (!records) return Fail(records.error());
    const std::string csv = MeasurementsCsv(*records);
    std::fwrite(csv.data(), 1, csv.size(), stdout);
    std::fprintf(stderr, "boxd: %zu measurements\n", records->size());
    return kExitOk;
}

}  // namespace

void AddExport(CLI::App& app, Runner& run) {
    auto opts = std::make_shared<ExportOptions>();
    CLI::App* sub = app.add_subcommand(
        "export",
        "Print the stored measurements as CSV with their billing, oldest first (what GET "
        "/v1/measurements.csv gives)");
    sub->add_option("--data-dir", opts->data_dir, "the daemon's data folder (storage.data_dir)")
        ->required();
    sub->add_option("--since", opts->since,
                    "only those finished at or after this UTC date or time (2026-12-05, "
                    "2026-12-05T10:00:00Z)");
    sub->callback([opts, &run] { run = [opts] { return RunExport(*opts); }; });
}

}  // namespace boxd::cli
