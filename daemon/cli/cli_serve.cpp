// `boxd serve`: the daemon (SPEC section 6).
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <memory>

#include "daemon/cli/build_info.h"
#include "daemon/cli/cli.h"
#include "daemon/service/serve_config.h"
#include "daemon/service/service_loop.h"
#include "daemon/service/sha256.h"

namespace boxd::cli {

namespace {

struct ServeOptions {
    std::string config;
    std::string listen;
    std::string data_dir;
};

// The daemon runs for months: glibc would give each of its many threads (HTTP connections,
// measurement workers) an arena of its own, up to eight per core, and keep what each once held —
// the RSS crept from 100 to 290 MB over a dozen measurements. Two arenas serve two cores; the
// measurement service trims the heap after each measurement (MeasurementService::Run).
void BoundTheAllocator() { mallopt(M_ARENA_MAX, 2); }

int RunServe(const ServeOptions& o) {
    BoundTheAllocator();
    ServeOverrides overrides;
    if (!o.listen.empty()) overrides.listen = o.listen;
    if (!o.data_dir.empty()) overrides.data_dir = o.data_dir;
    auto config = LoadServeConfig(o.config, overrides);
    if (!config) return Fail(config.error());
    auto sha256 = Sha256OfFile("/proc/self/exe");
    if (!sha256) return Fail(sha256.error());
    const SoftwareIdentity software{BuildVersion(), BuildCommit(), *sha256};
    Status served = RunService(std::move(*config), o.config, overrides, software);
    return served ? kExitOk : Fail(served.error());
}

}  // namespace

void AddServe(CLI::App& app, Runner& run) {
    auto opts = std::make_shared<ServeOptions>();
    CLI::App* sub = app.add_subcommand(
        "serve", "Run the daemon: the REST/JSON API, MQTT and the operator page (docs/daemon.md)");
    sub->add_option("--config", opts->config, "YAML config file (see config/sim.yaml)")->required();
    sub->add_option("--listen", opts->listen, "HOST:PORT to listen on (overrides server.listen)");
    sub->add_option("--data-dir", opts->data_dir,
                    "folder for results, clouds and sessions (overrides storage.data_dir)");
    sub->callback([opts, &run] { run = [opts] { return RunServe(*opts); }; });
}

}  // namespace boxd::cli
