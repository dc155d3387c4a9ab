// `boxd import-dump --dump DIR --config FILE --out DIR (--poses N | --angles A,B,...)`: turns a
// Kinect dump recorded on a station (fakenect-record while the table stopped at each pose) into
// a boxd session, with the station's calibration and camera from its config.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "daemon/cli/cli.h"
#include "drivers/driver_registry.h"
#include "drivers/dump_import.h"
#include "drivers/freenect_camera.h"
#include "drivers/station_config.h"
#include "pipeline/core/json_text.h"
#include "pipeline/io/session_io.h"

namespace boxd::cli {

namespace {

namespace fs = std::filesystem;

struct ImportOptions {
    fs::path dump;
    fs::path config;
    fs::path out;
    bool force = false;
    DumpImportOptions import;
};

// The station the dump was recorded on: its calibration (required: a session without one
// cannot be measured), its camera's intrinsics (the Kinect's unless the config sets them) and
// depth unit, and its table's direction.
Result<DumpStation> StationOf(const fs::path& path) {
    auto config = LoadStationConfig(path);
    if (!config) return config.error();
    if (!config->calibration) {
        return Error{ErrorCode::kInvalidInput,
                     "--config " + path.string() +
                         ": has no calibration section (boxd calibrate writes one)"};
    }
    DumpStation station;
    station.camera = config->camera.intrinsics.value_or(KinectIntrinsics());
    if (station.camera.width != 640 || station.camera.height != 480) {
        return Error{ErrorCode::kInvalidInput,
                     "--config " + path.string() +
                         ": camera.intrinsics must be for the Kinect's 640 x 480 depth image"};
    }
    station.camera.depth_unit_m = config->camera.depth_unit_m;
    station.calibration = *config->calibration;
    station.direction = ParseDirection(config->turntable.direction);
    return station;
}

int RunImport(const ImportOptions& o) {
    auto station = StationOf(o.config);
    if (!station) return Fail(station.error());
    if (auto st = CheckOutFolder(o.out, o.force); !st) return Fail(st.error());
    auto imported = ImportDump(o.dump, o.import, *station);
    if (!imported) return Fail(imported.error());
    if (auto st = WriteSession(imported->session, o.out); !st) return Fail(st.error());
    nlohmann::json poses = nlohmann::json::array();
    for (const StillStretch& s : imported->stretches) {
        if (s.count >= o.import.frames_per_pose) poses.push_back({s.first, s.first + s.count - 1});
    }
    const nlohmann::json summary = {{"session", o.out.string()},
                                    {"source", imported->session.source},
                                    {"depth_frames", imported->depth_frames},
                                    {"poses", imported->session.poses.size()},
                                    {"still_frames", poses},
                                    {"noise_floor", imported->noise_floor},
                                    {"motion_threshold", imported->threshold},
                                    {"frames_per_pose", o.import.frames_per_pose}};
    std::printf("%s\n", JsonText(summary).c_str());
    return kExitOk;
}

}  // namespace

void AddImportDump(CLI::App& app, Runner& run) {
    auto o = std::make_shared<ImportOptions>();
    CLI::App* sub =
        app.add_subcommand("import-dump",
                           "Turn a Kinect dump (fakenect-record) of a parcel on the station into a "
                           "session: the table's stops are found where the depth stands still");
    sub->add_option("--dump", o->dump, "the dump folder (INDEX.txt and its frames)")->required();
    sub->add_option("--config", o->config,
                    "the station's config: its calibration, camera and turntable direction")
        ->required();
    sub->add_option("--out", o->out, "Session folder to write")->required();
    sub->add_option("--poses", o->import.poses, "the table's stops, evenly spaced over a turn");
    sub->add_option("--angles", o->import.angles_deg,
                    "or the stops' table angles in degrees, in recording order")
        ->delimiter(',');
    sub->add_option("--frames", o->import.frames_per_pose,
                    "frames kept from each stop, its middle ones (default 5)");
    sub->add_option("--first", o->import.first_frame,
                    "the first depth frame used (0-based; the frames before it are left out)");
    sub->add_option("--last", o->import.last_frame, "the last depth frame used (default: the end)");
    sub->add_flag("--force", o->force, "Write into a folder that is not empty");
    sub->callback([&run, o] { run = [o] { return RunImport(*o); }; });
}

}  // namespace boxd::cli
