// The station config file: `camera:`, `capture:`, `calibration:` and their composition with the
// `turntable:` section.
#include "drivers/station_config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>

namespace boxd {

namespace {

Error KeyError(const std::string& key, const std::string& what) {
    return Error{ErrorCode::kInvalidInput, key + ": " + what};
}

// One YAML key: how to read its value, given the node and the key's full dotted name.
using Reader = std::function<Status(const YAML::Node&, const std::string&)>;

template <typename T>
Reader Value(T& target) {
    return [&target](const YAML::Node& node, const std::string& key) -> Status {
        try {
            target = node.as<T>();
            return OkStatus();
        } catch (const YAML::Exception&) {
            return KeyError(key, "wrong type");
        }
    };
}

// Reads every key of the map `node` (section `prefix`) with `readers`; an unknown key or a
// value that is not a map is an error naming it.
Status ReadMap(const YAML::Node& node, const std::string& prefix,
               const std::map<std::string, Reader>& readers) {
    if (!node || node.IsNull()) return OkStatus();
    if (!node.IsMap()) return KeyError(prefix, "must be a map");
    std::set<std::string> seen;
    for (const auto& item : node) {
        const std::string name = item.first.Scalar();
        const std::string key = prefix + "." + name;
        // YAML keeps both of two equal keys; which one counts would be a guess.
        if (!seen.insert(name).second) return KeyError(key, "given twice");
        const auto it = readers.find(name);
        if (it == readers.end()) return KeyError(key, "unknown key");
        if (auto st = it->second(item.second, key); !st) return st;
    }
    return OkStatus();
}

Reader Vector3(Eigen::Vector3d& target) {
    return [&target](const YAML::Node& node, const std::string& key) -> Status {
        if (!node.IsSequence() || node.size() != 3) return KeyError(key, "must be [x, y, z]");
        try {
            for (int i = 0; i < 3; ++i) target[i] = node[i].as<double>();
        } catch (const YAML::Exception&) {
            return KeyError(key, "wrong type");
        }
        return OkStatus();
    };
}

Reader Noise(NoiseModel& target) {
    return [&target](const YAML::Node& node, const std::string& key) -> Status {
        std::string name;
        if (auto st = Value(name)(node, key); !st) return st;
        auto model = ParseNoiseModel(name);
        if (!model)
            return KeyError(key, "must be none, kinect, realsense or tof, got '" + name + "'");
        target = *model;
        return OkStatus();
    };
}

Reader Seed(std::uint64_t& target) {
    return [&target](const YAML::Node& node, const std::string& key) -> Status {
        long long value = 0;
        if (auto st = Value(value)(node, key); !st) return st;
        if (value < 0) return KeyError(key, "must not be negative");
        target = static_cast<std::uint64_t>(value);
        return OkStatus();
    };
}

// A value that may be absent: set only where the key is given.
template <typename T>
Reader OptionalValue(std::optional<T>& target) {
    return [&target](const YAML::Node& node, const std::string& key) -> Status {
        T value{};
        if (auto st = Value(value)(node, key); !st) return st;
        target = value;
        return OkStatus();
    };
}

Reader Intrinsics(std::optional<CameraIntrinsics>& target) {
    return [&target](const YAML::Node& node, const std::string& key) -> Status {
        CameraIntrinsics k;
        if (auto st = ReadMap(node, key,
                              {{"width", Value(k.width)},
                               {"height", Value(k.height)},
                               {"fx", Value(k.fx)},
                               {"fy", Value(k.fy)},
                               {"cx", Value(k.cx)},
                               {"cy", Value(k.cy)}});
            !st) {
            return st;
        }
        target = k;
        return OkStatus();
    };
}

Status ReadSimulated(const YAML::Node& node, const std::string& key, SimulatedCameraConfig& c) {
    SyntheticStationConfig& s = c.station;
    SyntheticBox& b = s.box;
    SyntheticCameraPose& p = s.camera_pose;
    const std::map<std::string, Reader> box = {
        {"length_m", Value(b.length_m)},     {"width_m", Value(b.width_m)},
        {"height_m", Value(b.height_m)},     {"offset_x_m", Value(b.offset_x_m)},
        {"offset_y_m", Value(b.offset_y_m)}, {"yaw_deg", Value(b.yaw_deg)},
    };
    const std::map<std::string, Reader> pose = {
        {"distance_m", Value(p.distance_m)},
        {"elevation_deg", Value(p.elevation_deg)},
        {"aim_height_m", Value(p.aim_height_m)},
    };
    return ReadMap(
        node, key,
        {
            {"box", [&](const YAML::Node& n, const std::string& k) { return ReadMap(n, k, box); }},
            {"camera_pose",
             [&](const YAML::Node& n, const std::string& k) { return ReadMap(n, k, pose); }},
            {"disc_radius_m", Value(s.disc_radius_m)},
            {"disc_thickness_m", Value(s.disc_thickness_m)},
            {"floor_drop_m", Value(s.floor_drop_m)},
            {"noise", Noise(s.noise)},
            {"seed", Seed(s.seed)},
            {"angle_error_deg", Value(s.angle_error_deg)},
            {"calib_center_error_m", Value(s.calib_center_error_m)},
            {"calib_axis_error_deg", Value(s.calib_axis_error_deg)},
            {"true_depth_offset_m", Value(s.true_depth_offset_m)},
            {"frame_interval_ms", Value(c.frame_interval_ms)},
        });
}

}  // namespace

Status CameraConfig::Validate() const {
    if (driver != "openni2" && driver != "freenect" && driver != "simulated" &&
        driver != "replay") {
        return KeyError("camera.driver",
                        "must be openni2, freenect, simulated or replay, got '" + driver + "'");
    }
    if (!(depth_unit_m > 0.0) || depth_unit_m > 0.1) {
        return KeyError("camera.depth_unit_m", "must be in (0, 0.1] metres");
    }
    if (intrinsics) {
        if (auto st = intrinsics->Validate("camera.intrinsics"); !st) {
            return Error{ErrorCode::kInvalidInput, st.error().message};
        }
    }
    if (driver == "openni2") return openni2.Validate();
    if (driver == "freenect") return freenect.Validate();
    if (driver == "simulated") return simulated.Validate();
    return replay.Validate();
}

Result<CameraConfig> ParseCameraConfig(const YAML::Node& node) {
    CameraConfig c;
    OpenNi2CameraConfig& o = c.openni2;
    const std::map<std::string, Reader> openni2 = {
        {"uri", Value(o.uri)},
        {"width", Value(o.width)},
        {"height", Value(o.height)},
        {"fps", Value(o.fps)},
        {"depth_mode", Value(o.depth_mode)},
        {"recover_attempts", Value(o.recover_attempts)},
        {"usb_reset", Value(o.usb_reset)},
        {"reopen_delay_ms", Value(o.reopen_delay_ms)},
    };
    FreenectCameraConfig& f = c.freenect;
    const std::map<std::string, Reader> freenect = {
        {"index", Value(f.index)},
        {"serial", Value(f.serial)},
        {"depth_format", Value(f.depth_format)},
        {"tilt_deg", OptionalValue(f.tilt_deg)},  // absent: the motor is left alone
        {"led", Value(f.led)},
        {"recover_attempts", Value(f.recover_attempts)},
        {"usb_reset", Value(f.usb_reset)},
        {"reopen_delay_ms", Value(f.reopen_delay_ms)},
    };
    if (auto st = ReadMap(
            node, "camera",
            {
                {"driver", Value(c.driver)},
                {"depth_unit_m", Value(c.depth_unit_m)},
                {"intrinsics", Intrinsics(c.intrinsics)},
                {"openni2",
                 [&](const YAML::Node& n, const std::string& k) { return ReadMap(n, k, openni2); }},
                {"freenect", [&](const YAML::Node& n,
                                 const std::string& k) { return ReadMap(n, k, freenect); }},
                {"simulated",
                 [&](const YAML::Node& n, const std::string& k) {
                     return ReadSimulated(n, k, c.simulated);
                 }},
                {"replay",
                 [&](const YAML::Node& n, const std::string& k) {
                     return ReadMap(n, k, {{"session", Value(c.replay.session)}});
                 }},
            });
        !st) {
        return st.error();
    }
    // The simulated camera renders with the configured intrinsics and depth unit.
    if (c.intrinsics) c.simulated.station.camera = *c.intrinsics;
    c.simulated.station.camera.depth_unit_m = c.depth_unit_m;
    if (auto st = c.Validate(); !st) return st.error();
    return c;
}

Result<CaptureConfig> ParseCaptureConfig(const YAML::Node& node) {
    CaptureConfig c;
    if (auto st = ReadMap(node, "capture",
                          {
                              {"poses", Value(c.poses)},
                              {"angles_deg", Value(c.angles_deg)},
                              {"frames_per_pose", Value(c.frames_per_pose)},
                              {"drop_frames", Value(c.drop_frames)},
                              {"settle_ms", Value(c.settle_ms)},
                              {"grab_timeout_ms", Value(c.grab_timeout_ms)},
                              {"sweep", Value(c.sweep)},
                              {"order", Value(c.order)},
                              {"target_uncertainty_m", Value(c.target_uncertainty_m)},
                          });
        !st) {
        return st.error();
    }
    if (auto st = c.Validate(); !st) return st.error();
    return c;
}

Result<StationCalibration> ParseCalibration(const YAML::Node& node) {
    StationCalibration c;
    if (auto st = ReadMap(node, "calibration",
                          {
                              {"table_center_m", Vector3(c.table_center_m)},
                              {"table_axis", Vector3(c.table_axis)},
                              {"depth_offset_m", Value(c.depth_offset_m)},
                              {"depth_scale", Value(c.depth_scale)},
                              {"focal_scale", Value(c.focal_scale)},
                              {"multipath_albedo", Value(c.multipath_albedo)},
                              {"edge_growth_px", Value(c.edge_growth_px)},
                              {"depth_pattern_m", Value(c.depth_pattern_m)},
                          });
        !st) {
        return st.error();
    }
    if (auto st = c.Validate("calibration"); !st) {
        return Error{ErrorCode::kInvalidInput, st.error().message};
    }
    return c;
}

Result<StationConfig> ParseStationConfig(const YAML::Node& document) {
    const YAML::Node& root = document;  // const: lookups must not add keys
    StationConfig config;
    if (root && !root.IsNull() && !root.IsMap()) {
        return Error{ErrorCode::kInvalidInput, "config: must be a map of sections"};
    }
    for (const auto& item : root) {
        const std::string name = item.first.Scalar();
        if (std::count_if(root.begin(), root.end(), [&name](const auto& other) {
                return other.first.Scalar() == name;
            }) > 1) {
            return KeyError(name, "section given twice");
        }
        const bool known = name == "turntable" || name == "camera" || name == "capture" ||
                           name == "calibration" || name == "scale" ||
                           std::find(kOtherConfigSections.begin(), kOtherConfigSections.end(),
                                     name) != kOtherConfigSections.end();
        if (!known) return KeyError(name, "unknown section");
    }
    auto turntable = ParseTurntableConfig(root["turntable"]);
    if (!turntable) return turntable.error();
    config.turntable = *turntable;
    auto camera = ParseCameraConfig(root["camera"]);
    if (!camera) return camera.error();
    config.camera = *camera;
    auto capture = ParseCaptureConfig(root["capture"]);
    if (!capture) return capture.error();
    config.capture = *capture;
    auto scale = ParseScaleConfig(root["scale"]);
    if (!scale) return scale.error();
    config.scale = *scale;
    if (root["calibration"] && !root["calibration"].IsNull()) {
        auto calibration = ParseCalibration(root["calibration"]);
        if (!calibration) return calibration.error();
        config.calibration = *calibration;
    }
    return config;
}

namespace {

// Returns the YAML document at `path` (`what` names it in the error: "config", "calibration").
Result<YAML::Node> LoadYamlFile(const std::filesystem::path& path, const std::string& what) {
    try {
        return YAML::LoadFile(path.string());
    } catch (const YAML::BadFile&) {
        return Error{ErrorCode::kInvalidInput,
                     path.string() + ": cannot read the " + what + " file"};
    } catch (const YAML::Exception& e) {
        return Error{ErrorCode::kInvalidInput,
                     path.string() + ": line " + std::to_string(e.mark.line + 1) + ": " + e.msg};
    }
}

}  // namespace

Result<YAML::Node> LoadConfigSections(const std::filesystem::path& path) {
    auto root = LoadYamlFile(path, "config");
    if (root && !root->IsMap()) {
        return Error{ErrorCode::kInvalidInput, path.string() + ": must be a map of sections"};
    }
    return root;
}

Result<StationCalibration> LoadCalibrationFile(const std::filesystem::path& path) {
    auto root = LoadYamlFile(path, "calibration");
    if (!root) return root.error();
    const YAML::Node& doc = *root;  // const: lookups must not add keys
    if (!doc.IsMap() || !doc["calibration"]) {
        return Error{ErrorCode::kInvalidInput,
                     path.string() +
                         ": calibration: missing (a file written by `boxd calibrate "
                         "--out`, or a station config, holds a calibration: section)"};
    }
    auto c = ParseCalibration(doc["calibration"]);
    if (!c) return Error{ErrorCode::kInvalidInput, path.string() + ": " + c.error().message};
    return c;
}

Result<StationConfig> LoadStationConfig(const std::filesystem::path& path) {
    auto root = LoadYamlFile(path, "config");
    if (!root) return root.error();
    auto config = ParseStationConfig(*root);
    if (!config)
        return Error{ErrorCode::kInvalidInput, path.string() + ": " + config.error().message};
    // A relative replay session path is relative to the config file, not the working folder.
    std::string& session = config->camera.replay.session;
    if (!session.empty() && std::filesystem::path(session).is_relative()) {
        session = (path.parent_path() / session).lexically_normal().string();
    }
    return config;
}

}  // namespace boxd
