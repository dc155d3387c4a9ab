#pragma once
// The daemon's own config sections (`server:`, `storage:`, `mqtt:` and `measurement:` in the YAML
// file), validated at start: a bad value names its key ("server.listen: ...") and stops the
// start.

#include <cstddef>
#include <filesystem>
#include <string>

#include "pipeline/core/result.h"
#include "pipeline/measure_config.h"

namespace YAML {
class Node;
}

namespace boxd {

// A TCP listen address, "HOST:PORT" ("[::1]:8080" for IPv6).
struct ListenAddress {
    std::string host;
    int port = 0;  // 0 picks a free port
};

// Returns the address in `text`, or an error naming `key`.
Result<ListenAddress> ParseListenAddress(const std::string& text, const std::string& key);

// The `server:` section.
struct ServerConfig {
    std::string listen = "127.0.0.1:8080";   // TCP address; "" serves the Unix socket only
    std::string unix_socket;                 // optional Unix socket path, instead or as well
    std::string bearer_token;                // when set, POSTs need "Authorization: Bearer <it>"
    bool protect_reads = false;              // ... and with this, GETs too
    std::string unix_socket_mode = "0660";   // octal permissions of the socket file
    std::string unix_socket_group;           // group of the socket file ("" keeps the daemon's)
    std::size_t max_body_bytes = 64 * 1024;  // larger request bodies get 413
    int wait_timeout_s = 600;                // longest a POST /v1/measure?wait=1 blocks
    int threads = 16;                        // HTTP worker threads (a ?wait=1 request holds one)
    int max_connections = 256;               // ... added on demand up to this many connections
    // The operator page (GET /): its folder ("" finds the installed one, share/boxd/web beside
    // the binary, or the source tree's daemon/web) and three.js (Debian's libjs-three).
    std::string web_dir;
    std::string three_js = "/usr/share/javascript/three/three.min.js";

    // Returns an error naming the first invalid field ("server.<field>: ..."), or Ok.
    Status Validate() const;
    bool operator==(const ServerConfig&) const = default;
};

// The `storage:` section.
struct StorageConfig {
    std::string data_dir = "/var/lib/boxd";  // SQLite database, clouds/ and sessions/
    int retention = 1000;        // finished measurements kept; older rows and files are deleted
    bool keep_sessions = false;  // also keep each measurement's captured session folder

    // Returns an error naming the first invalid field ("storage.<field>: ..."), or Ok.
    Status Validate() const;
};

// The `mqtt:` section: publish every finished measurement and the state to a broker (a fleet's
// message bus). Absent: nothing is published.
struct MqttConfig {
    bool enabled = false;      // the section is present
    std::string host;          // the broker
    int port = 0;              // 0: 1883, or 8883 with tls
    std::string station_id;    // topics boxd/<station_id>/...: letters, digits, '.', '_', '-'
    std::string username;      // optional
    std::string password;      // optional, needs username
    bool tls = false;          // TLS to the broker, checked against the system's CAs ...
    std::string tls_ca_file;   // ... or this CA file
    int keepalive_s = 30;      // the broker declares the station offline after 1.5 times this
    int queue_limit = 1000;    // measurements kept while the broker is away (then the oldest go)
    int reconnect_max_s = 60;  // reconnect backoff: 1 s, doubling up to this

    // Returns an error naming the first invalid field ("mqtt.<field>: ..."), or Ok.
    Status Validate() const;
    // Returns the port to connect to (the default for plain or TLS when port is 0).
    int EffectivePort() const { return port != 0 ? port : (tls ? 8883 : 1883); }
    bool operator==(const MqttConfig&) const = default;
};

// Returns the config read from a `server:` YAML node (missing keys keep their defaults;
// unknown keys, wrong types and invalid values are errors naming the key).
Result<ServerConfig> ParseServerConfig(const YAML::Node& node);
// Same for the `storage:` section.
Result<StorageConfig> ParseStorageConfig(const YAML::Node& node);
// Same for the `mqtt:` section (absent or null: not enabled).
Result<MqttConfig> ParseMqttConfig(const YAML::Node& node);
// Sets what the `measurement:` section gives of `config` (absent or null: nothing): the
// station's word on what the measurement may assume and report. `max_uncertainty_m` (a larger
// 95% bound is refused UNCERTAIN) and `calibration_center_sigma_m` (how well the station's
// calibration placed the table's centre: where no alignment fixes the centre, the bounds rest on
// it; pipeline/registration/pose_graph.h).
Status ParseMeasurementConfig(const YAML::Node& node, MeasureConfig& config);
// Returns the defaults with the `measurement:` section of the config file at `file` applied
// (what `boxd measure --config` replays a station's sessions with). INVALID_INPUT naming the
// file and the key when it cannot be read or a value is wrong.
Result<MeasureConfig> LoadMeasurementConfig(const std::filesystem::path& file);

}  // namespace boxd
