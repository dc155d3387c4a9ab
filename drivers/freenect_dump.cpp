#include "drivers/freenect_dump.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "drivers/depth_camera.h"
#include "pipeline/core/kinect_disparity.h"

namespace boxd {

namespace {

namespace fs = std::filesystem;

// The size of libfreenect's freenect_raw_tilt_state: three int16 counts, the int8 tilt angle,
// padding, and the 32-bit tilt status (freenect_camera.cpp checks it against the header).
constexpr std::size_t kTiltStateBytes = 12;

Error DumpError(const fs::path& dir, const std::string& what) {
    return CameraError("fakenect dump " + dir.string() + ": " + what);
}

// Parses "<type>-<time>-<timestamp>..." as fakenect does.
bool ParseName(const std::string& name, DumpRecord* record) {
    char type = 0;
    double time = 0.0;
    unsigned int timestamp = 0;
    if (std::sscanf(name.c_str(), "%c-%lf-%u", &type, &time, &timestamp) != 3) return false;
    if (type != 'd' && type != 'r' && type != 'a') return false;
    if (!std::isfinite(time) || time < 0.0) return false;
    record->type = type;
    record->time_s = time;
    record->timestamp = timestamp;
    record->file = name;
    return true;
}

// Returns the offset of the pixel data after a one-line header, or npos.
std::size_t DataOffset(const std::string& bytes) {
    const std::size_t eol = bytes.find('\n');
    return eol == std::string::npos ? std::string::npos : eol + 1;
}

Result<std::string> ReadBytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return CameraError("cannot read " + path.string());
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

// Checks one record's file the way fakenect will use it: it reads every listed file whole (and
// ends the process when one cannot be opened, or stops the replay when one is empty).
Status CheckRecordFile(const fs::path& dir, const DumpRecord& r, int line) {
    const std::string where = " (INDEX.txt line " + std::to_string(line) + ")";
    std::error_code ec;
    const fs::path path = dir / r.file;
    if (!fs::is_regular_file(path, ec)) return DumpError(dir, r.file + " is missing" + where);
    if (r.type == 'd') {
        auto frame = ReadDumpDepth(path);
        if (!frame) return DumpError(dir, frame.error().message + where);
        return OkStatus();
    }
    std::ifstream in(path, std::ios::binary);
    if (!in || in.peek() == std::ifstream::traits_type::eof()) {
        return DumpError(dir, r.file + " cannot be read or is empty" + where);
    }
    return OkStatus();
}

}  // namespace

Result<std::vector<std::uint16_t>> ReadDumpDepth(const fs::path& path) {
    auto bytes = ReadBytes(path);
    if (!bytes) return bytes.error();
    const std::size_t offset = DataOffset(*bytes);
    // fakenect finds the header's end with strchr: a NUL before it hides it.
    if (offset == std::string::npos || bytes->compare(0, 2, "P5") != 0 ||
        bytes->find('\0') < offset) {
        return CameraError(path.filename().string() + " has no PGM header line");
    }
    const std::size_t data = bytes->size() - offset;
    if (data != kKinectDepthBytes) {
        return CameraError(path.filename().string() + " holds " + std::to_string(data) +
                           " bytes of depth, a 640 x 480 frame " +
                           std::to_string(kKinectDepthBytes) + ": truncated or not a Kinect frame");
    }
    std::vector<std::uint16_t> raw(kKinectDepthBytes / 2);
    const auto* p = reinterpret_cast<const unsigned char*>(bytes->data() + offset);
    for (std::size_t i = 0; i < raw.size(); ++i) {
        raw[i] = static_cast<std::uint16_t>(p[2 * i] | (p[2 * i + 1] << 8));  // little-endian
    }
    return raw;
}

Result<DumpIndex> CheckDump(const fs::path& dir) {
    std::ifstream in(dir / "INDEX.txt", std::ios::binary);
    if (!in) return DumpError(dir, "no INDEX.txt");
    DumpIndex index;
    index.dir = dir;
    std::string line;
    int number = 0;
    bool ended = false;  // an empty line: fakenect stops there
    while (std::getline(in, line)) {
        ++number;
        if (line.empty()) {
            ended = true;
            continue;
        }
        if (ended)
            return DumpError(dir, "INDEX.txt has an empty line before line " +
                                      std::to_string(number) + ": the replay would stop there");
        DumpRecord r;
        if (!ParseName(line, &r)) {
            return DumpError(dir, "INDEX.txt line " + std::to_string(number) + " '" + line +
                                      "' is not <d|r|a>-<time>-<timestamp>.<ext>");
        }
        if (!index.records.empty()) {
            const double pause = r.time_s - index.records.back().time_s;
            if (pause < 0.0 || pause > kDumpMaxPauseS) {
                return DumpError(dir,
                                 "INDEX.txt line " + std::to_string(number) + " is " +
                                     std::to_string(pause) +
                                     " s after the line before: not one recording in time order");
            }
        }
        if (auto st = CheckRecordFile(dir, r, number); !st) return st.error();
        if (r.type == 'd') ++index.depth_frames;
        index.records.push_back(std::move(r));
    }
    if (index.depth_frames == 0) return DumpError(dir, "INDEX.txt lists no depth frame");
    return index;
}

Result<DumpWriter> DumpWriter::Create(const fs::path& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::ofstream index(dir / "INDEX.txt", std::ios::binary | std::ios::trunc);
    if (ec || !index) return DumpError(dir, "cannot create INDEX.txt");
    return DumpWriter(dir);
}

Status DumpWriter::Append(const DumpRecord& record, const std::string& bytes) {
    std::ofstream out(dir_ / record.file, std::ios::binary | std::ios::trunc);
    out << bytes;
    out.close();  // a write that fails on closing (a full disk) is not listed
    if (!out) return DumpError(dir_, "cannot write " + record.file);
    std::ofstream index(dir_ / "INDEX.txt", std::ios::binary | std::ios::app);
    index << record.file << '\n';
    index.close();
    if (!index) return DumpError(dir_, "cannot append to INDEX.txt");
    return OkStatus();
}

namespace {
std::string RecordName(char type, double time_s, std::uint32_t timestamp, const char* ext) {
    char name[96];
    std::snprintf(name, sizeof(name), "%c-%.6f-%u.%s", type, time_s, timestamp, ext);
    return name;
}
}  // namespace

Status DumpWriter::AddDepth(double time_s, std::uint32_t timestamp,
                            const std::vector<std::uint16_t>& raw) {
    if (raw.size() * 2 != kKinectDepthBytes) {
        return DumpError(dir_, "a depth frame must be 640 x 480 raw values");
    }
    std::string bytes = "P5 640 480 65535\n";
    const std::size_t header = bytes.size();
    bytes.resize(header + kKinectDepthBytes);
    for (std::size_t i = 0; i < raw.size(); ++i) {
        bytes[header + 2 * i] = static_cast<char>(raw[i] & 0xff);
        bytes[header + 2 * i + 1] = static_cast<char>(raw[i] >> 8);
    }
    return Append({'d', time_s, timestamp, RecordName('d', time_s, timestamp, "pgm")}, bytes);
}

Status DumpWriter::AddAccel(double time_s, std::int16_t ax, std::int16_t ay, std::int16_t az,
                            std::int8_t tilt_half_deg) {
    std::string bytes(kTiltStateBytes, '\0');
    const std::int16_t counts[3] = {ax, ay, az};
    std::memcpy(bytes.data(), counts, sizeof(counts));  // host order, as the recorder writes
    bytes[6] = static_cast<char>(tilt_half_deg);
    return Append({'a', time_s, 0, RecordName('a', time_s, 0, "dump")}, bytes);
}

std::vector<std::uint16_t> RawDisparityToDepth(const std::vector<std::uint16_t>& raw,
                                               double depth_unit_m) {
    const KinectDepthTable& levels = KinectDisparityDepths();
    std::vector<std::uint16_t> depth(raw.size(), 0);
    for (std::size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] <= kKinectMaxRawDisparity) depth[i] = DepthValue(levels[raw[i]] / depth_unit_m);
    }
    return depth;
}

}  // namespace boxd
