#pragma once
// The whole config file of `boxd serve`: the daemon's `server:`, `storage:` and `mqtt:` sections
// plus the station's `turntable:`, `camera:`, `capture:` and `calibration:` sections, with the
// command line's --listen / --data-dir applied on top.

#include <filesystem>
#include <optional>
#include <string>

#include "daemon/service/daemon_config.h"
#include "daemon/service/device_station.h"
#include "pipeline/core/result.h"

namespace boxd {

struct ServeOverrides {
    std::optional<std::string> listen;    // --listen HOST:PORT
    std::optional<std::string> data_dir;  // --data-dir DIR
};

struct ServeConfig {
    ServerConfig server;
    StorageConfig storage;
    MqttConfig mqtt;
    DeviceStationConfig station;
};

// Returns the validated config in `file` with `overrides` applied, or an INVALID_INPUT error
// naming the file and the key (or the line of a YAML syntax error).
Result<ServeConfig> LoadServeConfig(const std::filesystem::path& file,
                                    const ServeOverrides& overrides);

}  // namespace boxd
