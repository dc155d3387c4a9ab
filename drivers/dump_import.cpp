#include "drivers/dump_import.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "drivers/freenect_dump.h"
#include "pipeline/core/kinect_disparity.h"

namespace boxd {

namespace {

namespace fs = std::filesystem;

Error OptionError(const std::string& what) { return Error{ErrorCode::kInvalidInput, what}; }

// Fewer pixels read in both frames than this: the frames cannot be compared (a covered lens).
constexpr int kMinCommonReadings = 1000;

// The depth frames of the dump, in order.
std::vector<fs::path> DepthFiles(const DumpIndex& index) {
    std::vector<fs::path> files;
    for (const DumpRecord& r : index.records) {
        if (r.type == 'd') files.push_back(index.dir / r.file);
    }
    return files;
}

// The share of changed pixels between consecutive frames, reading one frame at a time.
Result<std::vector<double>> ConsecutiveChanges(const std::vector<fs::path>& files, int levels) {
    std::vector<double> changes;
    std::vector<std::uint16_t> previous;
    for (const fs::path& file : files) {
        auto raw = ReadDumpDepth(file);
        if (!raw) return raw.error();
        if (!previous.empty()) changes.push_back(ChangedFraction(previous, *raw, levels));
        previous = std::move(*raw);
    }
    return changes;
}

// Splits the frames into still stretches against each stretch's first frame.
Result<std::vector<StillStretch>> FindStretches(const std::vector<fs::path>& files, int levels,
                                                double threshold) {
    std::vector<StillStretch> stretches;
    std::vector<std::uint16_t> reference;
    for (std::size_t i = 0; i < files.size(); ++i) {
        auto raw = ReadDumpDepth(files[i]);
        if (!raw) return raw.error();
        if (reference.empty() || ChangedFraction(reference, *raw, levels) > threshold) {
            stretches.push_back({static_cast<int>(i), 0});
            reference = std::move(*raw);
        }
        ++stretches.back().count;
    }
    return stretches;
}

std::string Describe(const std::vector<StillStretch>& stretches, int min_count) {
    std::ostringstream out;
    int listed = 0;
    for (const StillStretch& s : stretches) {
        if (s.count < min_count) continue;
        out << (listed++ ? ", " : "frames ") << s.first << "-" << s.first + s.count - 1;
    }
    return listed ? out.str() : "none";
}

}  // namespace

Status DumpImportOptions::Validate() const {
    if (poses < 0 || poses > 360) return OptionError("--poses: must be 1..360");
    if ((poses == 0) == angles_deg.empty()) {
        return OptionError("give the table's stops: --poses N (evenly spaced) or --angles A,B,...");
    }
    if (angles_deg.size() > 360) return OptionError("--angles: at most 360");
    for (double a : angles_deg) {
        if (!std::isfinite(a)) return OptionError("--angles: must be numbers");
    }
    if (frames_per_pose < 1 || frames_per_pose > 64) return OptionError("--frames: must be 1..64");
    if (first_frame < 0 || (last_frame >= 0 && last_frame < first_frame)) {
        return OptionError("--first/--last: must be frame numbers, first <= last");
    }
    if (motion_levels < 0 || motion_levels > 100) return OptionError("motion levels: 0..100");
    if (!(motion_factor >= 1.0 && motion_factor <= 100.0)) {
        return OptionError("motion factor: must be 1..100");
    }
    return OkStatus();
}

std::vector<double> DumpImportOptions::Angles() const {
    if (!angles_deg.empty()) return angles_deg;
    std::vector<double> angles;
    for (int i = 0; i < poses; ++i) angles.push_back(360.0 * i / poses);
    return angles;
}

double ChangedFraction(const std::vector<std::uint16_t>& a, const std::vector<std::uint16_t>& b,
                       int levels) {
    long common = 0, changed = 0;
    const std::size_t n = std::min(a.size(), b.size());
    for (std::size_t i = 0; i < n; ++i) {
        if (a[i] > kKinectMaxRawDisparity || b[i] > kKinectMaxRawDisparity) continue;
        ++common;
        if (std::abs(int{a[i]} - int{b[i]}) > levels) ++changed;
    }
    if (common < kMinCommonReadings) return 1.0;
    return static_cast<double>(changed) / static_cast<double>(common);
}

namespace {

// The share of changed pixels between two still frames: the quietest of the consecutive pairs.
// The stops given hold at least stops x (frames - 1) still pairs; the percentile taken is half
// that share, so it lies among the still pairs however long the turns between them are.
double NoiseFloor(std::vector<double> changes, const DumpImportOptions& options) {
    if (changes.empty()) return 0.0;
    const double still = static_cast<double>(options.Angles().size()) *
                         (options.frames_per_pose - 1) / static_cast<double>(changes.size());
    const double q = std::clamp(0.5 * still, 0.0, 0.5);
    auto at = changes.begin() + static_cast<std::ptrdiff_t>(q * (changes.size() - 1));
    std::nth_element(changes.begin(), at, changes.end());
    return *at;
}

// The poses' frames: the middle `frames_per_pose` of each stretch, as depth.
Status ReadPoses(const std::vector<fs::path>& files, const std::vector<StillStretch>& stretches,
                 const DumpImportOptions& options, Session& session) {
    const std::vector<double> angles = options.Angles();
    for (std::size_t k = 0; k < stretches.size(); ++k) {
        SessionPose pose;
        pose.angle_deg = angles[k];
        const int first = stretches[k].first + (stretches[k].count - options.frames_per_pose) / 2;
        for (int f = first; f < first + options.frames_per_pose; ++f) {
            auto raw = ReadDumpDepth(files[static_cast<std::size_t>(f)]);
            if (!raw) return raw.error();
            DepthImage image(kKinectDepthWidth, kKinectDepthHeight);
            image.pixels = RawDisparityToDepth(*raw, session.camera.depth_unit_m);
            pose.frames.push_back(std::move(image));
        }
        session.poses.push_back(std::move(pose));
    }
    return OkStatus();
}

}  // namespace

Result<DumpImport> ImportDump(const fs::path& dir, const DumpImportOptions& options,
                              const DumpStation& station) {
    if (auto st = options.Validate(); !st) return st.error();
    auto index = CheckDump(dir);
    if (!index) return index.error();
    std::vector<fs::path> files = DepthFiles(*index);
    DumpImport out;
    out.depth_frames = static_cast<int>(files.size());
    const int last = options.last_frame < 0 ? out.depth_frames - 1 : options.last_frame;
    if (options.first_frame > last || last >= out.depth_frames) {
        return OptionError("--first/--last: the dump has depth frames 0-" +
                           std::to_string(out.depth_frames - 1));
    }
    files = std::vector<fs::path>(files.begin() + options.first_frame, files.begin() + last + 1);
    auto changes = ConsecutiveChanges(files, options.motion_levels);
    if (!changes) return changes.error();
    out.noise_floor = NoiseFloor(std::move(*changes), options);
    // At least a few hundred pixels of a frame must change (a noise-free recording's floor is 0).
    out.threshold = std::max(options.motion_factor * out.noise_floor, 0.002);
    auto stretches = FindStretches(files, options.motion_levels, out.threshold);
    if (!stretches) return stretches.error();
    std::vector<StillStretch> poses;
    for (const StillStretch& s : *stretches) {
        if (s.count >= options.frames_per_pose) poses.push_back(s);
    }
    for (StillStretch& s : *stretches) s.first += options.first_frame;  // the dump's numbering
    if (poses.size() != options.Angles().size()) {
        return OptionError(dir.string() + ": " + std::to_string(poses.size()) +
                           " still stretches of at least " +
                           std::to_string(options.frames_per_pose) + " frames (" +
                           Describe(*stretches, options.frames_per_pose) + ") but " +
                           std::to_string(options.Angles().size()) +
                           " table stops were given (--first and --last leave frames out)");
    }
    out.stretches = std::move(*stretches);
    out.session.source = "freenect";
    out.session.camera = station.camera;
    out.session.calibration = station.calibration;
    out.session.direction = station.direction;
    if (auto st = ReadPoses(files, poses, options, out.session); !st) return st.error();
    return out;
}

}  // namespace boxd
