#include "daemon/service/daemon_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <set>

#include "drivers/config_keys.h"
#include "drivers/station_config.h"

namespace boxd {

using config_keys::CheckKeys;
using config_keys::ConfigError;
using config_keys::ReadKey;

Result<ListenAddress> ParseListenAddress(const std::string& text, const std::string& key) {
    ListenAddress a;
    std::string port;
    if (!text.empty() && text.front() == '[') {
        const auto close = text.find(']');
        if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':') {
            return ConfigError(key, "'" + text + "' is not [HOST]:PORT");
        }
        a.host = text.substr(1, close - 1);
        port = text.substr(close + 2);
    } else {
        const auto colon = text.rfind(':');
        if (colon == std::string::npos || text.find(':') != colon) {
            return ConfigError(key, "'" + text + "' is not HOST:PORT");
        }
        a.host = text.substr(0, colon);
        port = text.substr(colon + 1);
    }
    if (a.host.empty()) return ConfigError(key, "'" + text + "' has no host");
    const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), a.port);
    if (ec != std::errc() || end != port.data() + port.size() || port.empty() || a.port < 0 ||
        a.port > 65535) {
        return ConfigError(key, "'" + text + "' has no port in 0..65535");
    }
    return a;
}

Status ServerConfig::Validate() const {
    if (listen.empty() && unix_socket.empty()) {
        return ConfigError("server.listen", "empty, and no server.unix_socket either");
    }
    if (!listen.empty()) {
        auto a = ParseListenAddress(listen, "server.listen");
        if (!a) return a.error();
    }
    if (!unix_socket.empty() && unix_socket.size() >= 108) {
        // sockaddr_un.sun_path holds 108 bytes including the terminator.
        return ConfigError("server.unix_socket", "path longer than 107 characters");
    }
    if (unix_socket_mode.size() < 3 || unix_socket_mode.size() > 4 ||
        unix_socket_mode.find_first_not_of("01234567") != std::string::npos) {
        return ConfigError("server.unix_socket_mode",
                           "'" + unix_socket_mode + "' is not an octal mode such as 0660");
    }
    if (protect_reads && bearer_token.empty()) {
        return ConfigError("server.protect_reads", "needs server.bearer_token");
    }
    if (bearer_token.find_first_of(" \t\r\n") != std::string::npos) {
        return ConfigError("server.bearer_token", "must not contain white space");
    }
    if (max_body_bytes < 64) return ConfigError("server.max_body_bytes", "must be at least 64");
    if (wait_timeout_s < 1) return ConfigError("server.wait_timeout_s", "must be at least 1");
    if (threads < 2 || threads > 256) return ConfigError("server.threads", "must be in 2..256");
    if (max_connections < threads || max_connections > 4096) {
        return ConfigError("server.max_connections", "must be in server.threads..4096");
    }
    return OkStatus();
}

Status StorageConfig::Validate() const {
    if (data_dir.empty()) return ConfigError("storage.data_dir", "must not be empty");
    if (retention < 1) return ConfigError("storage.retention", "must be at least 1");
    return OkStatus();
}

Status MqttConfig::Validate() const {
    if (!enabled) return OkStatus();
    if (host.empty()) return ConfigError("mqtt.host", "must be given");
    if (port < 0 || port > 65535) return ConfigError("mqtt.port", "must be in 0..65535");
    if (station_id.empty() || station_id.size() > 64 ||
        !std::all_of(station_id.begin(), station_id.end(), [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
        })) {
        return ConfigError("mqtt.station_id",
                           "must be 1 to 64 letters, digits, '.', '_' or '-' (it names topics)");
    }
    if (!password.empty() && username.empty()) {
        return ConfigError("mqtt.password", "needs mqtt.username");
    }
    if (!tls_ca_file.empty() && !tls) return ConfigError("mqtt.tls_ca_file", "needs mqtt.tls");
    if (keepalive_s < 5 || keepalive_s > 3600) {
        return ConfigError("mqtt.keepalive_s", "must be in 5..3600");
    }
    if (queue_limit < 1 || queue_limit > 100000) {
        return ConfigError("mqtt.queue_limit", "must be in 1..100000");
    }
    if (reconnect_max_s < 1 || reconnect_max_s > 3600) {
        return ConfigError("mqtt.reconnect_max_s", "must be in 1..3600");
    }
    return OkStatus();
}

Result<ServerConfig> ParseServerConfig(const YAML::Node& node) {
    ServerConfig c;
    if (!node || node.IsNull()) return c;
    if (auto s = CheckKeys(node, "server",
                           {"listen", "unix_socket", "unix_socket_mode", "unix_socket_group",
                            "bearer_token", "protect_reads", "max_body_bytes", "wait_timeout_s",
                            "threads", "max_connections", "web_dir", "three_js"});
        !s) {
        return s.error();
    }
    long long max_body = static_cast<long long>(c.max_body_bytes);
    for (Status s : {ReadKey(node, "server", "listen", c.listen),
                     ReadKey(node, "server", "unix_socket", c.unix_socket),
                     ReadKey(node, "server", "unix_socket_mode", c.unix_socket_mode),
                     ReadKey(node, "server", "unix_socket_group", c.unix_socket_group),
                     ReadKey(node, "server", "bearer_token", c.bearer_token),
                     ReadKey(node, "server", "protect_reads", c.protect_reads),
                     ReadKey(node, "server", "max_body_bytes", max_body),
                     ReadKey(node, "server", "wait_timeout_s", c.wait_timeout_s),
                     ReadKey(node, "server", "threads", c.threads),
                     ReadKey(node, "server", "max_connections", c.max_connections),
                     ReadKey(node, "server", "web_dir", c.web_dir),
                     ReadKey(node, "server", "three_js", c.three_js)}) {
        if (!s) return s.error();
    }
    if (max_body < 0) return ConfigError("server.max_body_bytes", "must not be negative");
    c.max_body_bytes = static_cast<std::size_t>(max_body);
    if (auto s = c.Validate(); !s) return s.error();
    return c;
}

Result<StorageConfig> ParseStorageConfig(const YAML::Node& node) {
    StorageConfig c;
    if (!node || node.IsNull()) return c;
    if (auto s = CheckKeys(node, "storage", {"data_dir", "retention", "keep_sessions"}); !s) {
        return s.error();
    }
    for (Status s : {ReadKey(node, "storage", "data_dir", c.data_dir),
                     ReadKey(node, "storage", "retention", c.retention),
                     ReadKey(node, "storage", "keep_sessions", c.keep_sessions)}) {
        if (!s) return s.error();
    }
    if (auto s = c.Validate(); !s) return s.error();
    return c;
}

Status ParseMeasurementConfig(const YAML::Node& node, MeasureConfig& config) {
    if (!node || node.IsNull()) return OkStatus();
    if (auto s =
            CheckKeys(node, "measurement", {"max_uncertainty_m", "calibration_center_sigma_m"});
        !s) {
        return s;
    }
    MeasureConfig c = config;
    for (Status s : {ReadKey(node, "measurement", "max_uncertainty_m", c.refusal.max_uncertainty_m),
                     ReadKey(node, "measurement", "calibration_center_sigma_m",
                             c.pose_graph.calibration_center_sigma_m)}) {
        if (!s) return s;
    }
    if (!(c.refusal.max_uncertainty_m > 0.0 && c.refusal.max_uncertainty_m <= 1.0)) {
        return ConfigError("measurement.max_uncertainty_m", "must be in (0, 1] metres");
    }
    if (!(c.pose_graph.calibration_center_sigma_m > 0.0 &&
          c.pose_graph.calibration_center_sigma_m <= 0.1)) {
        return ConfigError("measurement.calibration_center_sigma_m", "must be in (0, 0.1] metres");
    }
    config = c;
    return OkStatus();
}

Result<MeasureConfig> LoadMeasurementConfig(const std::filesystem::path& file) {
    auto root = LoadConfigSections(file);
    if (!root) return root.error();
    MeasureConfig config;
    if (Status s = ParseMeasurementConfig((*root)["measurement"], config); !s) {
        return Error{ErrorCode::kInvalidInput, file.string() + ": " + s.error().message};
    }
    return config;
}

Result<MqttConfig> ParseMqttConfig(const YAML::Node& node) {
    MqttConfig c;
    if (!node || node.IsNull()) return c;
    if (auto s = CheckKeys(node, "mqtt",
                           {"host", "port", "station_id", "username", "password", "tls",
                            "tls_ca_file", "keepalive_s", "queue_limit", "reconnect_max_s"});
        !s) {
        return s.error();
    }
    c.enabled = true;
    for (Status s :
         {ReadKey(node, "mqtt", "host", c.host), ReadKey(node, "mqtt", "port", c.port),
          ReadKey(node, "mqtt", "station_id", c.station_id),
          ReadKey(node, "mqtt", "username", c.username),
          ReadKey(node, "mqtt", "password", c.password), ReadKey(node, "mqtt", "tls", c.tls),
          ReadKey(node, "mqtt", "tls_ca_file", c.tls_ca_file),
          ReadKey(node, "mqtt", "keepalive_s", c.keepalive_s),
          ReadKey(node, "mqtt", "queue_limit", c.queue_limit),
          ReadKey(node, "mqtt", "reconnect_max_s", c.reconnect_max_s)}) {
        if (!s) return s.error();
    }
    if (auto s = c.Validate(); !s) return s.error();
    return c;
}

}  // namespace boxd
