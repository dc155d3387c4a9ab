#pragma once
// Kinect dump folders in libfreenect's fakenect format (what `fakenect-record` writes and
// Debian's fakenect library replays through the libfreenect API): an INDEX.txt naming one file
// per line, in recording order, each named "<type>-<wall clock s>-<device timestamp>.<ext>":
//   d-....pgm  a depth frame: "P5 640 480 65535\n" and 640 x 480 little-endian 11-bit raw
//              disparities (2047 = no reading);
//   r-....ppm  a colour frame ("P6 640 480 255\n" and RGB bytes);
//   a-....dump the accelerometer and tilt motor state (libfreenect's freenect_raw_tilt_state).
// fakenect ends the process on a dump it cannot read (a missing INDEX.txt or file, a header
// without a line end) and reads past a short frame, so boxd checks a dump before replaying it
// (CheckDump) and reads dumps itself where it converts them (ReadDumpDepth).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/core/result.h"

namespace boxd {

inline constexpr int kKinectDepthWidth = 640;
inline constexpr int kKinectDepthHeight = 480;
inline constexpr std::size_t kKinectDepthBytes = 640 * 480 * 2;
// The longest pause between two records a replay may hold: fakenect sleeps through recorded
// pauses (holding the camera meanwhile), and a Kinect streams 30 frames a second, so a pause of
// 60 frames is not one continuous recording.
inline constexpr double kDumpMaxPauseS = 2.0;

// One INDEX.txt line.
struct DumpRecord {
    char type = 'd';              // 'd' depth, 'r' colour, 'a' accelerometer
    double time_s = 0.0;          // the recording host's wall clock
    std::uint32_t timestamp = 0;  // the device's frame timestamp
    std::string file;             // the file name, relative to the dump folder
};

// A dump folder that fakenect can replay to the end.
struct DumpIndex {
    std::filesystem::path dir;
    std::vector<DumpRecord> records;
    int depth_frames = 0;
};

// Reads `dir`'s INDEX.txt and checks what fakenect would stumble over: every listed file present
// and readable and not empty, names it can parse, depth frames whole (a header line without a
// NUL, then 614 400 bytes), records in time order without a pause over kDumpMaxPauseS, at least
// one depth frame, no empty line before the end (fakenect stops at one). CAMERA_ERROR "fakenect
// dump <dir>: <what>, <where>".
Result<DumpIndex> CheckDump(const std::filesystem::path& dir);

// Returns the 640 x 480 raw disparities of the depth frame file `path`; CAMERA_ERROR when it is
// not a whole one.
Result<std::vector<std::uint16_t>> ReadDumpDepth(const std::filesystem::path& path);

// Writes a dump folder record by record (the tests' simulated Kinect, conversions).
class DumpWriter {
public:
    // Creates `dir` (and its parents) and an empty INDEX.txt; CAMERA_ERROR when it cannot.
    static Result<DumpWriter> Create(const std::filesystem::path& dir);

    // Appends a depth frame of 640 x 480 raw disparities recorded at `time_s`.
    Status AddDepth(double time_s, std::uint32_t timestamp, const std::vector<std::uint16_t>& raw);
    // Appends an accelerometer record: the raw counts (819 per g) and the motor's tilt angle in
    // half degrees, as libfreenect's freenect_raw_tilt_state holds them.
    Status AddAccel(double time_s, std::int16_t ax, std::int16_t ay, std::int16_t az,
                    std::int8_t tilt_half_deg);
    const std::filesystem::path& dir() const { return dir_; }

private:
    explicit DumpWriter(std::filesystem::path dir) : dir_(std::move(dir)) {}
    Status Append(const DumpRecord& record, const std::string& bytes);
    std::filesystem::path dir_;
};

// Converts a raw disparity frame to depth in `depth_unit_m` units with the Kinect v1 conversion
// (pipeline/core/kinect_disparity.h); 2047 and out-of-range values become 0 (no reading).
std::vector<std::uint16_t> RawDisparityToDepth(const std::vector<std::uint16_t>& raw,
                                               double depth_unit_m);

}  // namespace boxd
