#pragma once
// The service loop of `boxd serve`: brings the store, the station and the API up, tells systemd
// when it is ready, checks the stored records' chain and watches the metrological settings (the
// audit trail), pings the watchdog from its timer, reports state changes (STATUS=), reloads
// the config on SIGHUP when idle, and on SIGTERM aborts the running measurement, stops the table
// and exits.

#include <filesystem>

#include "daemon/service/serve_config.h"
#include "pipeline/core/result.h"
#include "pipeline/io/software_block.h"

namespace boxd {

// Runs the daemon with the validated `config` (read from `config_file` with `overrides`, which a
// reload reads again) until SIGTERM/SIGINT; returns Ok after a clean stop, or the error that kept
// it from starting (INVALID_CONFIG when the configured data folder or address cannot be used).
// `software` identifies the running program in the audit trail and in every result.
Status RunService(ServeConfig config, const std::filesystem::path& config_file,
                  const ServeOverrides& overrides, const SoftwareIdentity& software);

}  // namespace boxd
