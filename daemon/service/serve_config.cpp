#include "daemon/service/serve_config.h"

#include <yaml-cpp/yaml.h>

namespace boxd {

Result<ServeConfig> LoadServeConfig(const std::filesystem::path& file,
                                    const ServeOverrides& overrides) {
    auto fail = [&file](const std::string& what) {
        return Error{ErrorCode::kInvalidInput, file.string() + ": " + what};
    };
    auto loaded = LoadConfigSections(file);
    if (!loaded) return loaded.error();
    const YAML::Node& root = *loaded;

    ServeConfig config;
    auto server = ParseServerConfig(root["server"]);
    if (!server) return fail(server.error().message);
    config.server = *server;
    auto storage = ParseStorageConfig(root["storage"]);
    if (!storage) return fail(storage.error().message);
    config.storage = *storage;
    auto mqtt = ParseMqttConfig(root["mqtt"]);
    if (!mqtt) return fail(mqtt.error().message);
    config.mqtt = *mqtt;
    auto station = ParseStationConfig(root);
    if (!station) return fail(station.error().message);
    config.station.station = std::move(*station);
    config.station.config_file = std::filesystem::absolute(file);
    if (Status s = ParseMeasurementConfig(root["measurement"], config.station.measure); !s) {
        return fail(s.error().message);
    }
    if (Status s = config.station.measure.Validate(); !s) return fail(s.error().message);
    auto billing = ParseBillingConfig(root["billing"]);
    if (!billing) return fail(billing.error().message);
    config.station.billing = *billing;

    // The command line wins over the file, and is validated the same way.
    if (overrides.listen) {
        config.server.listen = *overrides.listen;
        if (Status s = config.server.Validate(); !s) {
            return Error{ErrorCode::kInvalidInput, "--listen: " + s.error().message};
        }
    }
    if (overrides.data_dir) {
        config.storage.data_dir = *overrides.data_dir;
        if (Status s = config.storage.Validate(); !s) {
            return Error{ErrorCode::kInvalidInput, "--data-dir: " + s.error().message};
        }
    }
    config.station.calibration_file =
        std::filesystem::path(config.storage.data_dir) / "calibration.json";
    return config;
}

}  // namespace boxd
