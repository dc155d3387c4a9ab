// `boxd synth`: renders a synthetic session (SPEC section 7) into a folder.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "daemon/cli/cli.h"
#include "drivers/sim/synthetic_objects.h"
#include "drivers/sim/synthetic_station.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/session_io.h"

namespace boxd::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct SynthOptions {
    fs::path out;
    std::vector<double> dims;
    int poses = 18;
    int frames = 4;
    std::uint64_t seed = 1;
    std::string noise = "kinect";
    std::vector<double> offset;
    double yaw_deg = 0.0;
    std::optional<double> distance_m, elevation_deg, aim_height_m;
    std::optional<double> angle_error_deg, calib_center_error_m, calib_axis_error_deg;
    std::optional<double> depth_offset_m, calib_depth_offset_error_m, focal_error_pct;
    std::optional<double> depth_unit_m;
    std::optional<int> move_at_pose;
    std::vector<double> move_by;
    std::vector<double> angles;
    // The object and its real-parcel features (SyntheticBox).
    std::string shape = "box";
    double edge_radius_m = 0.0, bulge_m = 0.0, bulge_top_m = 0.0;
    double strap_m = 0.0, strap_width_m = 0.025, label_m = 0.0, flap_deg = 0.0;
    double taper_m = 0.0;
    std::vector<double> second_dims, second_offset, dark_band;
    // The effects of real cameras (sensor_effects.h) on top of the noise model.
    std::optional<double> shadow_baseline_m, correlated_noise_m, correlation_px;
    std::optional<double> fixed_pattern_m, fixed_pattern_px, multipath_albedo;
    std::optional<int> edge_fattening_px;
    std::optional<int> intruder_pose;
    bool force = false;
};

// The units a frame may be recorded in: 16 bits of 0.01 mm reach 0.65 m, of 0.1 mm 6.5 m (past
// any depth camera's range here), of 10 mm 655 m.
constexpr double kMinDepthUnitM = 0.00001;
constexpr double kMaxDepthUnitM = 0.01;

// Returns the frame files a previous synthetic session in `dir` listed, or an error if `dir`
// holds anything else (so that user data is never overwritten without --force).
Result<std::vector<fs::path>> PreviousSyntheticFrames(const fs::path& dir, bool force) {
    std::error_code ec;
    if (!fs::exists(dir, ec)) return std::vector<fs::path>{};
    if (!fs::is_directory(dir, ec)) {
        return Error{ErrorCode::kInvalidInput,
                     "--out " + dir.string() + ": exists and is not a folder"};
    }
    if (fs::directory_iterator(dir, ec) == fs::directory_iterator()) {
        return std::vector<fs::path>{};
    }
    json previous;
    {
        std::ifstream in(dir / "session.json");
        previous = json::parse(in, nullptr, /*allow_exceptions=*/false);
    }
    const bool synthetic = previous.is_object() && previous.value("source", "") == "synthetic" &&
                           previous.value("format", "") == kSessionFormat;
    if (!synthetic) {
        if (force) return std::vector<fs::path>{};  // write over it, delete nothing
        return Error{ErrorCode::kInvalidInput,
                     "--out " + dir.string() +
                         ": folder is not empty and holds no synthetic session "
                         "(use --force to write into it anyway)"};
    }
    std::vector<fs::path> frames;
    if (previous.contains("poses") && previous["poses"].is_array()) {
        for (const json& pose : previous["poses"]) {
            if (!pose.is_object() || !pose.contains("frames") || !pose["frames"].is_array()) {
                continue;
            }
            for (const json& f : pose["frames"]) {
                if (!f.is_string()) continue;
                const fs::path rel = f.get<std::string>();
                const std::string s = rel.lexically_normal().string();
                if (rel.is_absolute() || s.rfind("..", 0) == 0) continue;  // never leave `dir`
                frames.push_back(rel.lexically_normal());
            }
        }
    }
    return frames;
}

// Removes the previous synthetic session's frames that the new session did not overwrite, and
// the folders they leave empty, so the folder holds exactly one session.
void RemoveStaleFrames(const fs::path& dir, const std::vector<fs::path>& previous,
                       const Session& session) {
    std::set<fs::path> current;
    for (const SessionPose& p : session.poses) {
        for (const std::string& f : p.frame_paths) current.insert(fs::path(f).lexically_normal());
    }
    std::error_code ec;
    for (const fs::path& rel : previous) {
        if (current.count(rel) || rel.extension() != ".png") continue;
        fs::remove(dir / rel, ec);
        const fs::path parent = (dir / rel).parent_path();
        if (parent != dir && fs::is_empty(parent, ec)) fs::remove(parent, ec);
    }
}

// Sets `to` from `from` where an option was given.
template <typename T>
void SetIfGiven(T& to, const std::optional<T>& from) {
    if (from) to = *from;
}

// Returns the noise model's parameters with the effects asked for, or none when none is.
std::optional<SensorNoiseParams> SensorEffects(const SynthOptions& o, NoiseModel model) {
    if (!o.shadow_baseline_m && !o.edge_fattening_px && !o.correlated_noise_m &&
        !o.fixed_pattern_m && !o.multipath_albedo) {
        return std::nullopt;
    }
    SensorNoiseParams p = DefaultSensorNoise(model);
    SetIfGiven(p.shadow_baseline_m, o.shadow_baseline_m);
    SetIfGiven(p.edge_fattening_px, o.edge_fattening_px);
    SetIfGiven(p.correlated_sigma_m, o.correlated_noise_m);
    SetIfGiven(p.correlation_px, o.correlation_px);
    SetIfGiven(p.fixed_pattern_m, o.fixed_pattern_m);
    SetIfGiven(p.fixed_pattern_px, o.fixed_pattern_px);
    SetIfGiven(p.multipath_albedo, o.multipath_albedo);
    return p;
}

Result<SyntheticStationConfig> MakeConfig(const SynthOptions& o) {
    SyntheticStationConfig c;
    c.box.length_m = o.dims.at(0);
    c.box.width_m = o.dims.at(1);
    c.box.height_m = o.dims.at(2);
    if (!o.offset.empty()) {
        c.box.offset_x_m = o.offset.at(0);
        c.box.offset_y_m = o.offset.at(1);
    }
    c.box.yaw_deg = o.yaw_deg;
    auto shape = ParseSyntheticShape(o.shape);
    if (!shape) return Error{ErrorCode::kInvalidInput, "--" + shape.error().message};
    c.box.shape = *shape;
    c.box.edge_radius_m = o.edge_radius_m;
    c.box.bulge_m = o.bulge_m;
    c.box.bulge_top_m = o.bulge_top_m;
    c.box.strap_thickness_m = o.strap_m;
    c.box.strap_width_m = o.strap_width_m;
    c.box.label_thickness_m = o.label_m;
    c.box.flap_deg = o.flap_deg;
    c.box.taper_m = o.taper_m;
    if (!o.second_dims.empty()) {
        SyntheticBox second;
        second.length_m = o.second_dims.at(0);
        second.width_m = o.second_dims.at(1);
        second.height_m = o.second_dims.at(2);
        if (o.second_offset.empty()) {
            return Error{ErrorCode::kInvalidInput, "--second-dims needs --second-offset"};
        }
        second.offset_x_m = o.second_offset.at(0);
        second.offset_y_m = o.second_offset.at(1);
        c.extra_objects.push_back(second);
    }
    c.intruder_pose = o.intruder_pose;
    if (!o.dark_band.empty()) {
        c.dark_from_m = o.dark_band.at(0);
        c.dark_to_m = o.dark_band.at(1);
    }
    SetIfGiven(c.camera_pose.distance_m, o.distance_m);
    SetIfGiven(c.camera_pose.elevation_deg, o.elevation_deg);
    SetIfGiven(c.camera_pose.aim_height_m, o.aim_height_m);
    auto noise = ParseNoiseModel(o.noise);
    if (!noise) return noise.error();
    c.noise = *noise;
    c.sensor_noise = SensorEffects(o, *noise);
    c.seed = o.seed;
    SetIfGiven(c.angle_error_deg, o.angle_error_deg);
    SetIfGiven(c.calib_center_error_m, o.calib_center_error_m);
    SetIfGiven(c.calib_axis_error_deg, o.calib_axis_error_deg);
    SetIfGiven(c.true_depth_offset_m, o.depth_offset_m);
    SetIfGiven(c.calib_depth_offset_error_m, o.calib_depth_offset_error_m);
    SetIfGiven(c.focal_error_pct, o.focal_error_pct);
    if (o.depth_unit_m) {
        if (!(*o.depth_unit_m >= kMinDepthUnitM && *o.depth_unit_m <= kMaxDepthUnitM)) {
            return Error{ErrorCode::kInvalidInput,
                         "--depth-unit-m: must be between 0.00001 and 0.01 m"};
        }
        c.camera.depth_unit_m = *o.depth_unit_m;
    }
    if (o.move_at_pose) {
        c.moved_at_pose = *o.move_at_pose;
        if (!o.move_by.empty()) {
            c.moved_dx_m = o.move_by.at(0);
            c.moved_dy_m = o.move_by.at(1);
            c.moved_dyaw_deg = o.move_by.at(2);
        }
    } else if (!o.move_by.empty()) {
        return Error{ErrorCode::kInvalidInput, "--move-by needs --move-at-pose"};
    }
    if (auto st = c.Validate(); !st) return st.error();
    return c;
}

int RunSynth(const SynthOptions& o) {
    const auto start = std::chrono::steady_clock::now();
    auto config = MakeConfig(o);
    if (!config) return Fail(config.error());
    auto previous = PreviousSyntheticFrames(o.out, o.force);
    if (!previous) return Fail(previous.error());

    auto session = o.angles.empty() ? RenderSyntheticSession(*config, o.poses, o.frames)
                                    : RenderSyntheticSession(*config, o.angles, o.frames);
    if (!session) return Fail(session.error());
    const auto rendered = std::chrono::steady_clock::now();
    spdlog::info("synth: rendered {} poses x {} frames ({} noise, seed {})", o.poses, o.frames,
                 o.noise, o.seed);
    if (auto st = WriteSession(*session, o.out); !st) return Fail(st.error());
    RemoveStaleFrames(o.out, *previous, *session);

    const auto end = std::chrono::steady_clock::now();
    auto ms = [](auto d) {
        return std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
    };
    std::error_code ec;
    const fs::path abs = fs::absolute(o.out, ec);
    json truth = nullptr;  // two objects have no single size
    if (const auto& gt = session->ground_truth) {
        truth = {{"length_m", gt->length_m}, {"width_m", gt->width_m}, {"height_m", gt->height_m}};
    }
    const json summary = {{"path", (ec ? o.out : abs).lexically_normal().string()},
                          {"poses", session->poses.size()},
                          {"frames", o.frames},
                          {"noise", NoiseModelName(config->noise)},
                          {"seed", o.seed},
                          {"ground_truth", truth},
                          {"elapsed_ms", ms(end - start)},
                          {"render_ms", ms(rendered - start)},
                          {"write_ms", ms(end - rendered)}};
    std::printf("%s\n", JsonText(summary).c_str());
    return kExitOk;
}

void AddSensorEffectOptions(CLI::App* sub, SynthOptions& o) {
    sub->add_option("--shadow-baseline-m", o.shadow_baseline_m,
                    "A second viewpoint this far along the camera's x axis (negative: -x) must "
                    "see a point too: a projector's or a second imager's shadows (m)");
    sub->add_option("--edge-fattening-px", o.edge_fattening_px,
                    "Nearer surfaces read this many pixels wider along x at depth edges (the "
                    "recorded calibration's edge_growth_px says so, as boxd calibrate learns it)");
    sub->add_option("--correlated-noise-m", o.correlated_noise_m,
                    "Smooth noise drawn every frame: sigma at 1 m (m), growing as depth^2");
    sub->add_option("--correlation-px", o.correlation_px,
                    "Spacing of the correlated noise's knots (pixels, default 16)");
    sub->add_option("--fixed-pattern-m", o.fixed_pattern_m,
                    "A bias pattern the same in every frame: its knots' sigma at 1 m (m), growing "
                    "as depth^2 (the recorded calibration's depth_pattern_m holds its spread over "
                    "the image, as boxd calibrate learns it)");
    sub->add_option("--fixed-pattern-px", o.fixed_pattern_px,
                    "Spacing of the fixed pattern's knots (pixels, default 64)");
    sub->add_option("--multipath-albedo", o.multipath_albedo,
                    "A time-of-flight camera's multipath: the surfaces' diffuse reflectance "
                    "(0-1; tof: 0.5, 0: none)");
}

}  // namespace

void AddSynth(CLI::App& app, Runner& run) {
    auto o = std::make_shared<SynthOptions>();
    CLI::App* sub = app.add_subcommand(
        "synth", "Render a synthetic session: a box on a turntable seen by a noisy depth camera");
    sub->add_option("--out", o->out, "Session folder to write")->required();
    sub->add_option("--dims", o->dims, "Box length, width, height (m)")->expected(3)->required();
    sub->add_option("--poses", o->poses, "Turntable poses over 360 degrees")->capture_default_str();
    sub->add_option("--frames", o->frames, "Depth frames per pose")->capture_default_str();
    sub->add_option("--seed", o->seed, "Random seed")->capture_default_str();
    sub->add_option("--noise", o->noise, "Sensor noise: kinect, realsense, tof or none")
        ->capture_default_str();
    sub->add_option("--offset", o->offset, "Box centre offset X Y from the axis (m)")->expected(2);
    sub->add_option("--yaw", o->yaw_deg, "Box yaw at pose 0 (deg)");
    sub->add_option("--distance", o->distance_m, "Camera distance to the aim point (m)");
    sub->add_option("--elevation", o->elevation_deg, "Camera elevation above the table (deg)");
    sub->add_option("--aim-height", o->aim_height_m, "Aim point height above the table (m)");
    sub->add_option("--angle-error-deg", o->angle_error_deg, "Sigma of the turntable angle error");
    sub->add_option("--calib-center-error-m", o->calib_center_error_m,
                    "Centre error of the recorded calibration (m)");
    sub->add_option("--calib-axis-error-deg", o->calib_axis_error_deg,
                    "Axis tilt error of the recorded calibration (deg)");
    sub->add_option("--depth-offset-m", o->depth_offset_m,
                    "Sensor depth bias: raw z = true z - offset (m)");
    sub->add_option("--calib-depth-offset-error-m", o->calib_depth_offset_error_m,
                    "Depth offset error of the recorded calibration (m, signed): it records the "
                    "sensor bias plus this; minus the bias records 0 (depth never calibrated)");
    sub->add_option("--focal-error-pct", o->focal_error_pct,
                    "The camera's true focal length is this many per cent longer than the "
                    "session's fx, fy (the recorded calibration keeps focal_scale 1)");
    sub->add_option("--depth-unit-m", o->depth_unit_m,
                    "Unit of the recorded frames (m), 0.00001 to 0.01: 0.001 (the default) "
                    "or 0.0001 as the camera's depth_mode 1mm or 100um records");
    sub->add_option("--move-at-pose", o->move_at_pose, "The box is moved from this pose on");
    sub->add_option("--move-by", o->move_by, "The move: DX DY (m) DYAW (deg)")->expected(3);
    sub->add_option("--angles", o->angles,
                    "Commanded pose angles (deg, any spacing); replaces --poses")
        ->delimiter(',');
    sub->add_option("--shape", o->shape,
                    "box, cylinder, lying_cylinder, l_shape, bag, prism, wedge, frustum, pyramid, "
                    "sack, lying_bottle, chamfered, box_on_box or handle")
        ->capture_default_str();
    sub->add_option("--edge-radius", o->edge_radius_m, "Rounded edges: radius (m)");
    sub->add_option("--bulge", o->bulge_m, "Side faces bulge out by this much (m)");
    sub->add_option("--bulge-top", o->bulge_top_m, "The top bulges out by this much (m)");
    sub->add_option("--strap", o->strap_m, "A strap over the top and both ends: thickness (m)");
    sub->add_option("--strap-width", o->strap_width_m, "The strap's width (m)")
        ->capture_default_str();
    sub->add_option("--label", o->label_m, "A label on a side face: thickness (m)");
    sub->add_option("--flap-deg", o->flap_deg, "A top flap opened by this angle (deg)");
    sub->add_option("--taper-m", o->taper_m,
                    "A frustum's sides come in by this much from the base to the top; a "
                    "chamfered carton's base by this much at 45 degrees (m)");
    sub->add_option("--second-dims", o->second_dims, "A second box: length, width, height (m)")
        ->expected(3);
    sub->add_option("--second-offset", o->second_offset, "The second box's centre X Y (m)")
        ->expected(2);
    sub->add_option("--intruder-pose", o->intruder_pose, "A hand reaches in at this pose");
    sub->add_option("--dark-band", o->dark_band,
                    "The objects read no depth between these heights (m): a dark or absorbing "
                    "material")
        ->expected(2);
    AddSensorEffectOptions(sub, *o);
    sub->add_flag("--force", o->force, "Write into a non-empty folder that holds no session");
    sub->callback([&run, o] { run = [o] { return RunSynth(*o); }; });
}

}  // namespace boxd::cli
