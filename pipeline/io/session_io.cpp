#include "pipeline/io/session_io.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "pipeline/core/json_text.h"
#include "pipeline/io/png16.h"
#include "pipeline/io/station_calibration_json.h"

namespace boxd {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

Error SessionError(const fs::path& file, const std::string& field, const std::string& why) {
    std::string msg = file.string() + ": ";
    if (!field.empty()) msg += field + ": ";
    return Error{ErrorCode::kInvalidSession, msg + why};
}

// Reads fields of session.json, remembering the file for error messages.
class JsonReader {
public:
    explicit JsonReader(fs::path file) : file_(std::move(file)) {}

    Result<const json*> Member(const json& obj, const std::string& parent, const std::string& key,
                               bool required = true) const {
        const std::string field = parent.empty() ? key : parent + "." + key;
        if (!obj.is_object()) return SessionError(file_, parent, "must be an object");
        auto it = obj.find(key);
        if (it == obj.end()) {
            if (required) return SessionError(file_, field, "missing required key");
            return static_cast<const json*>(nullptr);
        }
        return &*it;
    }

    Result<double> Number(const json& obj, const std::string& parent,
                          const std::string& key) const {
        auto m = Member(obj, parent, key);
        if (!m) return m.error();
        const std::string field = parent + "." + key;
        if (!(*m)->is_number()) return SessionError(file_, field, "must be a number");
        const double v = (*m)->get<double>();
        if (!std::isfinite(v)) return SessionError(file_, field, "must be finite");
        return v;
    }

    const fs::path& file() const { return file_; }

private:
    fs::path file_;
};

// Frames per pose: a capture averages a handful; a session claiming thousands would only cost
// memory (each 640 x 480 frame is 600 kB decoded). SPEC section 3's rules.
constexpr std::size_t kMaxFramesPerPose = 64;

// A frame path must stay inside the session folder.
bool IsContainedRelativePath(const std::string& p) {
    if (p.empty() || p.find('\0') != std::string::npos) return false;  // a NUL would cut the path
    const fs::path path(p);
    if (path.is_absolute() || path.has_root_name() || path.has_root_directory()) return false;
    for (const auto& part : path) {
        if (part == "..") return false;
    }
    return true;
}

Result<CameraIntrinsics> ParseCamera(const JsonReader& r, const json& root) {
    auto cam = r.Member(root, "", "camera");
    if (!cam) return cam.error();
    CameraIntrinsics c;
    const json& j = **cam;
    for (const char* key : {"width", "height"}) {
        auto m = r.Member(j, "camera", key);
        if (!m) return m.error();
        // Checked as 64-bit: 4294967936 must not pass as 640 after a cast to int.
        if (!(*m)->is_number_integer() || (*m)->get<std::int64_t>() < 1 ||
            (*m)->get<std::int64_t>() > 8192) {
            return SessionError(r.file(), std::string("camera.") + key,
                                "must be an integer in 1..8192");
        }
    }
    c.width = static_cast<int>(j["width"].get<std::int64_t>());
    c.height = static_cast<int>(j["height"].get<std::int64_t>());
    struct Field {
        const char* key;
        double* dst;
    };
    for (Field f : {Field{"fx", &c.fx}, Field{"fy", &c.fy}, Field{"cx", &c.cx}, Field{"cy", &c.cy},
                    Field{"depth_unit_m", &c.depth_unit_m}}) {
        auto v = r.Number(j, "camera", f.key);
        if (!v) return v.error();
        *f.dst = *v;
    }
    if (auto s = c.Validate("camera"); !s) return SessionError(r.file(), "", s.error().message);
    return c;
}

Result<StationCalibration> ParseCalibration(const JsonReader& r, const json& root) {
    auto cal = r.Member(root, "", "calibration");
    if (!cal) return cal.error();
    auto c = StationCalibrationFromJson(**cal, "calibration");
    if (!c) return SessionError(r.file(), "", c.error().message);
    return c;
}

Result<DepthImage> ReadFrame(const fs::path& file, const std::string& field,
                             const CameraIntrinsics& camera) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return SessionError(file, field, "file not found");
    // The camera's size is checked against the PNG header before a pixel is decoded: a header
    // claiming 65535 x 65535 costs nothing.
    auto img = ReadPng16(file, camera.width, camera.height);
    if (!img) return SessionError(file, field, img.error().message);
    return img;
}

Result<std::vector<SessionPose>> ParsePoses(const JsonReader& r, const json& root) {
    auto poses = r.Member(root, "", "poses");
    if (!poses) return poses.error();
    const json& arr = **poses;
    if (!arr.is_array()) return SessionError(r.file(), "poses", "must be an array");
    if (arr.empty() || arr.size() > 360) {
        return SessionError(r.file(), "poses",
                            "must hold 1 to 360 poses, has " + std::to_string(arr.size()));
    }
    std::vector<SessionPose> out(arr.size());
    for (std::size_t i = 0; i < arr.size(); ++i) {
        const std::string name = "poses[" + std::to_string(i) + "]";
        auto angle = r.Number(arr[i], name, "angle_deg");
        if (!angle) return angle.error();
        out[i].angle_deg = *angle;
        auto frames = r.Member(arr[i], name, "frames");
        if (!frames) return frames.error();
        const json& f = **frames;
        if (!f.is_array() || f.empty() || f.size() > kMaxFramesPerPose) {
            return SessionError(
                r.file(), name + ".frames",
                "must be an array of 1 to " + std::to_string(kMaxFramesPerPose) + " paths");
        }
        for (std::size_t k = 0; k < f.size(); ++k) {
            const std::string field = name + ".frames[" + std::to_string(k) + "]";
            if (!f[k].is_string()) return SessionError(r.file(), field, "must be a string");
            const std::string p = f[k].get<std::string>();
            if (!IsContainedRelativePath(p)) {
                std::string shown = p;
                for (std::size_t at; (at = shown.find('\0')) != std::string::npos;) {
                    shown.replace(at, 1, "\\0");
                }
                return SessionError(r.file(), field,
                                    "path '" + shown +
                                        "' must be relative and stay inside the session "
                                        "folder (no absolute paths, no '..', no NUL)");
            }
            out[i].frame_paths.push_back(p);
        }
    }
    return out;
}

// Returns frame k of pose i, read from its file under `dir`.
Result<DepthImage> LoadFrame(const fs::path& dir, const CameraIntrinsics& camera,
                             const SessionPose& pose, std::size_t i, std::size_t k) {
    const std::string field = "poses[" + std::to_string(i) + "].frames[" + std::to_string(k) + "]";
    // Nothing may leave a worker thread as an exception (std::terminate): memory running out
    // while decoding is this frame's error like any other.
    try {
        return ReadFrame(dir / pose.frame_paths[k], field, camera);
    } catch (const std::exception& e) {
        return SessionError(dir / pose.frame_paths[k], field,
                            std::string("cannot be decoded: ") + e.what());
    }
}

// Loads every frame of every pose, on two threads (PNG decoding dominates session loading).
Status LoadFrames(const fs::path& dir, const CameraIntrinsics& camera,
                  std::vector<SessionPose>& poses) {
    struct Job {
        std::size_t pose, frame;
    };
    std::vector<Job> jobs;
    for (std::size_t i = 0; i < poses.size(); ++i) {
        poses[i].frames.resize(poses[i].frame_paths.size());
        for (std::size_t k = 0; k < poses[i].frame_paths.size(); ++k) jobs.push_back({i, k});
    }
    std::vector<std::optional<Error>> errors(jobs.size());
    auto work = [&](std::size_t begin, std::size_t step) {
        for (std::size_t j = begin; j < jobs.size(); j += step) {
            const auto [i, k] = jobs[j];
            auto img = LoadFrame(dir, camera, poses[i], i, k);
            if (img) {
                poses[i].frames[k] = std::move(*img);
            } else {
                errors[j] = img.error();
            }
        }
    };
    std::thread helper(work, 1, 2);
    work(0, 2);
    helper.join();
    for (const auto& e : errors) {
        if (e) return *e;
    }
    return OkStatus();
}

const char* DirectionName(TurntableDirection d) {
    return d == TurntableDirection::kCcw ? "ccw" : "cw";
}

}  // namespace

Result<Session> LoadSession(const fs::path& dir) {
    auto s = LoadSessionHeader(dir);
    if (!s) return s.error();
    if (auto st = LoadFrames(dir, s->camera, s->poses); !st) return st.error();
    return s;
}

Result<std::vector<DepthImage>> LoadPoseFrames(const fs::path& dir, const Session& header,
                                               std::size_t pose) {
    if (pose >= header.poses.size()) {
        return Error{ErrorCode::kInternal, "LoadPoseFrames: no pose " + std::to_string(pose)};
    }
    const SessionPose& p = header.poses[pose];
    std::vector<DepthImage> frames(p.frame_paths.size());
    for (std::size_t k = 0; k < frames.size(); ++k) {
        auto img = LoadFrame(dir, header.camera, p, pose, k);
        if (!img) return img.error();
        frames[k] = std::move(*img);
    }
    return frames;
}

Result<Session> LoadSessionHeader(const fs::path& dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        return SessionError(dir, "", "session folder not found");
    }
    const fs::path file = dir / "session.json";
    std::ifstream in(file);
    if (!in) return SessionError(file, "", "cannot open session.json");
    json root;
    try {
        root = json::parse(in);
    } catch (const json::exception& e) {
        // Syntax errors, and numbers beyond a double's range (1e400).
        return SessionError(file, "", std::string("not valid JSON: ") + e.what());
    }
    JsonReader r(file);
    if (!root.is_object()) return SessionError(file, "", "must hold a JSON object");

    auto format = r.Member(root, "", "format");
    if (!format) return format.error();
    if (!(*format)->is_string() || (*format)->get<std::string>() != kSessionFormat) {
        return SessionError(
            file, "format",
            std::string("must be \"") + kSessionFormat + "\", got " + (*format)->dump());
    }

    Session s;
    if (auto src = r.Member(root, "", "source", false); src && *src && (**src).is_string()) {
        s.source = (**src).get<std::string>();
    }
    auto camera = ParseCamera(r, root);
    if (!camera) return camera.error();
    s.camera = *camera;
    auto calibration = ParseCalibration(r, root);
    if (!calibration) return calibration.error();
    s.calibration = *calibration;

    auto turntable = r.Member(root, "", "turntable");
    if (!turntable) return turntable.error();
    auto direction = r.Member(**turntable, "turntable", "direction");
    if (!direction) return direction.error();
    const std::string dir_name = (*direction)->is_string() ? (*direction)->get<std::string>() : "";
    if (dir_name == "ccw") {
        s.direction = TurntableDirection::kCcw;
    } else if (dir_name == "cw") {
        s.direction = TurntableDirection::kCw;
    } else {
        return SessionError(file, "turntable.direction", "must be \"ccw\" or \"cw\"");
    }

    auto poses = ParsePoses(r, root);
    if (!poses) return poses.error();
    s.poses = std::move(*poses);

    if (auto gt = r.Member(root, "", "ground_truth", false); gt && *gt) {
        BoxDimensions d;
        auto l = r.Number(**gt, "ground_truth", "length_m");
        auto w = r.Number(**gt, "ground_truth", "width_m");
        auto h = r.Number(**gt, "ground_truth", "height_m");
        if (!l) return l.error();
        if (!w) return w.error();
        if (!h) return h.error();
        d.length_m = *l;
        d.width_m = *w;
        d.height_m = *h;
        s.ground_truth = d;
    }

    return s;
}

Status WriteSession(const Session& session, const fs::path& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec)
        return Error{ErrorCode::kIoError, dir.string() + ": cannot create folder: " + ec.message()};

    json poses = json::array();
    std::vector<std::pair<fs::path, const DepthImage*>> pngs;
    for (std::size_t i = 0; i < session.poses.size(); ++i) {
        const SessionPose& p = session.poses[i];
        json frames = json::array();
        for (std::size_t k = 0; k < p.frames.size(); ++k) {
            const std::string rel =
                k < p.frame_paths.size() ? p.frame_paths[k] : SessionFramePath(i, k);
            if (!IsContainedRelativePath(rel)) {
                return Error{ErrorCode::kInvalidInput,
                             "frame path '" + rel + "' leaves the session folder"};
            }
            const fs::path file = dir / rel;
            fs::create_directories(file.parent_path(), ec);
            pngs.emplace_back(file, &p.frames[k]);
            frames.push_back(rel);
        }
        poses.push_back({{"angle_deg", p.angle_deg}, {"frames", frames}});
    }
    // PNG encoding dominates writing a session: two threads, like LoadFrames.
    std::vector<std::optional<Error>> errors(pngs.size());
    auto encode = [&](std::size_t begin, std::size_t step) {
        for (std::size_t j = begin; j < pngs.size(); j += step) {
            const auto& [file, img] = pngs[j];
            if (Status s = WritePng16(file, *img, 1); !s) errors[j] = s.error();
        }
    };
    std::thread helper(encode, 1, 2);
    encode(0, 2);
    helper.join();
    for (const auto& e : errors) {
        if (e) return *e;
    }
    const auto& c = session.camera;
    json root = {
        {"format", kSessionFormat},
        {"source", session.source},
        {"camera",
         {{"width", c.width},
          {"height", c.height},
          {"fx", c.fx},
          {"fy", c.fy},
          {"cx", c.cx},
          {"cy", c.cy},
          {"depth_unit_m", c.depth_unit_m}}},
        {"calibration", ToJson(session.calibration)},
        {"turntable", {{"direction", DirectionName(session.direction)}}},
        {"poses", poses},
    };
    if (session.ground_truth) {
        const auto& g = *session.ground_truth;
        root["ground_truth"] = {
            {"length_m", g.length_m}, {"width_m", g.width_m}, {"height_m", g.height_m}};
    }
    const fs::path file = dir / "session.json";
    const fs::path tmp = dir / "session.json.tmp";
    {
        std::ofstream out(tmp);
        out << JsonText(root, 2) << "\n";
        if (!out) return Error{ErrorCode::kIoError, tmp.string() + ": cannot write"};
    }
    fs::rename(tmp, file, ec);
    if (ec) return Error{ErrorCode::kIoError, file.string() + ": cannot write: " + ec.message()};
    return OkStatus();
}

}  // namespace boxd
