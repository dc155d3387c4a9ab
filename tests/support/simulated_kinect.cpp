#include "tests/support/simulated_kinect.h"

#include <cmath>
#include <sstream>

#include "drivers/freenect_camera.h"
#include "drivers/freenect_dump.h"
#include "drivers/sim/simulated_camera.h"
#include "pipeline/core/kinect_disparity.h"

namespace boxd::test {

namespace {

// The depth unit the frames are rendered in before encoding: fine enough that every disparity
// level the sensor model quantised to comes back as itself.
constexpr double kRenderUnitM = 0.0001;

std::vector<std::uint16_t> Encode(const DepthImage& image) {
    std::vector<std::uint16_t> raw(image.pixels.size(), kKinectNoReading);
    for (std::size_t i = 0; i < raw.size(); ++i) {
        if (!image.pixels[i]) continue;
        const double d = std::round(KinectRawDisparity(image.pixels[i] * kRenderUnitM));
        if (d >= 0.0 && d <= kKinectMaxRawDisparity) raw[i] = static_cast<std::uint16_t>(d);
    }
    return raw;
}

}  // namespace

SyntheticStationConfig AsKinect(SyntheticStationConfig station) {
    station.camera = KinectIntrinsics();
    station.camera.depth_unit_m = kRenderUnitM;
    station.noise = NoiseModel::kKinect;
    return station;
}

Result<int> WriteSimulatedKinectDump(const std::filesystem::path& dir,
                                     const SyntheticStationConfig& station,
                                     const KinectDumpPlan& plan) {
    auto writer = DumpWriter::Create(dir);
    if (!writer) return writer.error();
    double angle = plan.angles_deg.empty() ? 0.0 : plan.angles_deg.front();
    SimulatedCameraConfig config;
    config.station = AsKinect(station);
    SimulatedCamera camera(config, [&angle]() -> Result<double> { return angle; });
    if (auto st = camera.Open(); !st) return st.error();
    double t = 1'700'000'000.0;
    std::uint32_t stamp = 0;
    int written = 0;
    if (plan.accel_tilt_deg) {
        constexpr double kCountsPerG = 819.0;
        const double a = *plan.accel_tilt_deg * M_PI / 180.0;
        const auto y = static_cast<std::int16_t>(std::lround(kCountsPerG * std::cos(a)));
        const auto z = static_cast<std::int16_t>(std::lround(kCountsPerG * std::sin(a)));
        if (auto st = writer->AddAccel(t, 0, y, z, 0); !st) return st.error();
    }
    auto frame = [&]() -> Status {
        auto image = camera.Grab(std::chrono::milliseconds(1000));
        if (!image) return image.error();
        t += plan.frame_period_s;
        stamp += 1'000'000;
        ++written;
        return writer->AddDepth(t, stamp, Encode(*image));
    };
    for (std::size_t k = 0; k < plan.angles_deg.size(); ++k) {
        angle = plan.angles_deg[k];
        for (int f = 0; f < plan.frames_per_angle; ++f) {
            if (auto st = frame(); !st) return st.error();
        }
        if (k + 1 == plan.angles_deg.size()) break;
        const double to = plan.angles_deg[k + 1];
        for (int m = 1; m <= plan.motion_frames; ++m) {
            angle = plan.angles_deg[k] + (to - plan.angles_deg[k]) * m / (plan.motion_frames + 1);
            if (auto st = frame(); !st) return st.error();
        }
    }
    return written;
}

std::string CalibrationYaml(const SyntheticStationConfig& station) {
    const StationCalibration c = MakeSyntheticScene(station).recorded_calibration;
    std::ostringstream out;
    out.precision(9);
    out << "calibration:\n  table_center_m: [" << c.table_center_m.x() << ", "
        << c.table_center_m.y() << ", " << c.table_center_m.z() << "]\n  table_axis: ["
        << c.table_axis.x() << ", " << c.table_axis.y() << ", " << c.table_axis.z()
        << "]\n  depth_offset_m: " << c.depth_offset_m << "\n  depth_scale: " << c.depth_scale
        << "\n";
    return out.str();
}

std::vector<std::string> FakenectEnv(const std::filesystem::path& dump) {
    return {std::string("LD_LIBRARY_PATH=") + BOXD_FAKENECT_DIR, "FAKENECT_PATH=" + dump.string()};
}

}  // namespace boxd::test
