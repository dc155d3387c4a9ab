// `boxd verify --data-dir DIR`: checks a data folder's stored records against their hash chain
// and lists the metrological events — without changing anything, beside a running daemon too.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "daemon/cli/cli.h"
#include "daemon/service/audit_trail.h"
#include "daemon/service/record_chain.h"
#include "daemon/service/sqlite_db.h"
#include "pipeline/core/json_text.h"

namespace boxd::cli {

namespace {

using nlohmann::json;

struct VerifyOptions {
    std::string data_dir;
    int events = 20;
};

int RunVerify(const VerifyOptions& o) {
    auto opened = OpenDatabaseReadOnly(o.data_dir);
    if (!opened) {
        return Fail(Error{ErrorCode::kInvalidInput, "--data-dir: " + opened.error().message});
    }
    const DatabaseHandle db = std::move(*opened);
    auto chain = VerifyRecordChain(db.get());
    if (!chain) return Fail(chain.error());
    auto events = ReadAuditEvents(db.get(), o.events);
    if (!events) return Fail(events.error());
    auto counter = ReadEventCounter(db.get());
    if (!counter) return Fail(counter.error());
    json list = json::array();
    for (const AuditEvent& e : *events) list.push_back(ToJson(e));
    const json out = {
        {"records",
         {{"intact", chain->intact},
          {"checked", chain->records},
          {"unchained", chain->unchained},
          {"head", chain->head},
          {"problem", chain->problem.empty() ? json(nullptr) : json(chain->problem)}}},
        {"event_counter", *counter},
        {"events", list}};
    std::printf("%s\n", JsonText(out).c_str());
    if (!chain->intact) {
        std::fprintf(stderr, "boxd: the stored records fail their check: %s\n",
                     chain->problem.c_str());
        return kExitVerifyFailed;
    }
    std::fprintf(stderr, "boxd: %lld records intact%s\n", chain->records,
                 chain->unchained ? " (older records from before the chain are not checked)" : "");
    return kExitOk;
}

}  // namespace

void AddVerify(CLI::App& app, Runner& run) {
    auto opts = std::make_shared<VerifyOptions>();
    CLI::App* sub = app.add_subcommand(
        "verify",
        "Check a data folder's stored measurements against their hash chain and list the "
        "metrological events (exit 4 when a record was changed or deleted)");
    sub->add_option("--data-dir", opts->data_dir, "the daemon's data folder (storage.data_dir)")
        ->required();
    sub->add_option("--events", opts->events, "how many of the newest events to list")
        ->capture_default_str()
        ->check(CLI::Range(0, 100000));
    sub->callback([opts, &run] { run = [opts] { return RunVerify(*opts); }; });
}

}  // namespace boxd::cli
