// The simulated depth camera.
#include "drivers/sim/simulated_camera.h"

#include <cmath>
#include <random>
#include <thread>

#include "pipeline/core/mix_bits.h"

namespace boxd {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Reported angles closer than this are the same pose.
constexpr double kSamePoseDeg = 0.05;

}  // namespace

Status SimulatedCameraConfig::Validate() const {
    if (frame_interval_ms < 0 || frame_interval_ms > 10'000) {
        return Error{ErrorCode::kInvalidInput,
                     "camera.simulated.frame_interval_ms: must be 0..10000"};
    }
    if (auto st = station.Validate(); !st) {
        std::string message = st.error().message;
        // The station's own messages name the field; put them under the YAML section.
        if (message.rfind("camera", 0) == 0 && message.rfind("camera.", 0) != 0) {
            return Error{ErrorCode::kInvalidInput, "camera." + message};
        }
        return Error{ErrorCode::kInvalidInput, "camera.simulated." + message};
    }
    return OkStatus();
}

SimulatedCamera::SimulatedCamera(SimulatedCameraConfig config, AngleSource angle_deg)
    : config_(std::move(config)), angle_deg_(std::move(angle_deg)) {}

Status SimulatedCamera::Open() {
    if (auto st = config_.Validate(); !st) return CameraError(st.error().message);
    if (!angle_deg_) return CameraError("simulated camera: no turntable angle source");
    scene_ = MakeSyntheticScene(config_.station);
    open_ = true;
    pose_index_ = -1;
    streaming_since_ = std::chrono::steady_clock::now();
    last_frame_tick_ = -1;
    return OkStatus();
}

double SimulatedCamera::TrueAngleRad(double reported_deg) const {
    // The error belongs to the pose, not the frame: all frames of a pose see the same table.
    // It is drawn from the seed and the reported angle (0.01° steps), so it is repeatable.
    const auto key = static_cast<std::int64_t>(std::llround(reported_deg * 100.0));
    std::mt19937_64 rng(MixBits(config_.station.seed ^ MixBits(static_cast<std::uint64_t>(key))));
    std::normal_distribution<double> error(0.0, 1.0);
    const double error_deg = config_.station.angle_error_deg * error(rng);
    return (reported_deg + error_deg) * kDegToRad;
}

Result<DepthImage> SimulatedCamera::Grab(std::chrono::milliseconds timeout) {
    if (!open_) return CameraError("simulated camera: camera is not open");
    if (config_.frame_interval_ms > 0) {
        if (timeout.count() < config_.frame_interval_ms) {
            return CameraError("simulated camera: no depth frame within " +
                               std::to_string(timeout.count()) + " ms");
        }
        // The next frame the sensor exposes: at the next tick of its period, one frame per tick.
        const auto period = std::chrono::milliseconds(config_.frame_interval_ms);
        const auto since = std::chrono::steady_clock::now() - streaming_since_;
        const auto next = (since + period - std::chrono::nanoseconds(1)) / period;
        const long long tick = std::max(last_frame_tick_ + 1, static_cast<long long>(next));
        std::this_thread::sleep_until(streaming_since_ + tick * period);
        last_frame_tick_ = tick;
    }
    const Result<double> reported = angle_deg_();
    if (!reported) {
        return CameraError("simulated camera: cannot read the table angle: " +
                           reported.error().message);
    }
    if (pose_index_ < 0 || std::abs(*reported - last_reported_deg_) > kSamePoseDeg) {
        ++pose_index_;
        last_reported_deg_ = *reported;
    }
    const std::uint64_t frame_seed =
        MixBits(config_.station.seed + 0x5eedULL) ^ MixBits(frames_rendered_++);
    return RenderDepthFrame(scene_, TrueAngleRad(*reported), frame_seed, pose_index_);
}

std::string SimulatedCamera::Describe() const {
    const SyntheticBox& b = config_.station.box;
    char text[160];
    std::snprintf(text, sizeof(text),
                  "simulated %dx%d, box %.3f x %.3f x %.3f m, noise %s, seed %llu",
                  config_.station.camera.width, config_.station.camera.height, b.length_m,
                  b.width_m, b.height_m, NoiseModelName(config_.station.noise),
                  static_cast<unsigned long long>(config_.station.seed));
    return text;
}

}  // namespace boxd
