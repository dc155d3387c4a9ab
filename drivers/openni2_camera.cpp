#include "drivers/openni2_camera.h"

#include <OpenNI.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <mutex>
#include <thread>

#include "drivers/usb_devices.h"

namespace boxd {

namespace {

Error ConfigError(const std::string& field, const std::string& what) {
    return Error{ErrorCode::kInvalidInput, "camera.openni2." + field + ": " + what};
}

// OpenNI2 keeps global driver state; it is initialised once per process and never shut down,
// because some drivers' frame threads outlive their streams and would run into unloaded code.
Status InitializeOpenNi() {
    static std::once_flag once;
    static openni::Status status = openni::STATUS_OK;
    static std::string message;
    std::call_once(once, [] {
        status = openni::OpenNI::initialize();
        if (status != openni::STATUS_OK) message = openni::OpenNI::getExtendedError();
    });
    if (status != openni::STATUS_OK) return CameraError("openni2: cannot initialise: " + message);
    return OkStatus();
}

std::string LastOpenNiError() {
    std::string text = openni::OpenNI::getExtendedError();
    for (char& c : text) {
        if (c == '\n' || c == '\t') c = ' ';
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text.empty() ? "no detail from OpenNI2" : text;
}

bool IsDepthFormat(openni::PixelFormat f) {
    return f == openni::PIXEL_FORMAT_DEPTH_1_MM || f == openni::PIXEL_FORMAT_DEPTH_100_UM;
}

double FormatUnitM(openni::PixelFormat f) {
    return f == openni::PIXEL_FORMAT_DEPTH_100_UM ? 0.0001 : 0.001;
}

// The video-mode choice for a live device: the configured resolution and pixel format, the
// configured fps when offered (else the first match).
Result<openni::VideoMode> ChooseVideoMode(const openni::SensorInfo& info,
                                          const OpenNi2CameraConfig& config) {
    const openni::PixelFormat want = config.depth_mode == "100um"
                                         ? openni::PIXEL_FORMAT_DEPTH_100_UM
                                         : openni::PIXEL_FORMAT_DEPTH_1_MM;
    const auto& modes = info.getSupportedVideoModes();
    std::optional<openni::VideoMode> best;
    std::string offered;
    for (int i = 0; i < modes.getSize(); ++i) {
        const openni::VideoMode& m = modes[i];
        if (!offered.empty()) offered += ", ";
        offered += std::to_string(m.getResolutionX()) + "x" + std::to_string(m.getResolutionY()) +
                   "@" + std::to_string(m.getFps()) +
                   (m.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM ? " 100um"
                    : m.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM ? " 1mm"
                                                                            : " other");
        if (m.getPixelFormat() != want || m.getResolutionX() != config.width ||
            m.getResolutionY() != config.height) {
            continue;
        }
        if (!best || m.getFps() == config.fps) best = m;
    }
    if (!best) {
        return CameraError("openni2: no depth mode " + std::to_string(config.width) + "x" +
                           std::to_string(config.height) + " " + config.depth_mode +
                           " (the device offers: " + offered + ")");
    }
    return *best;
}

}  // namespace

double FocalLengthFromFov(int size_px, double fov_rad) {
    return size_px / 2.0 / std::tan(fov_rad / 2.0);
}

Status OpenNi2CameraConfig::Validate() const {
    if (width <= 0 || width > 4096) return ConfigError("width", "must be 1..4096");
    if (height <= 0 || height > 4096) return ConfigError("height", "must be 1..4096");
    if (fps <= 0 || fps > 1000) return ConfigError("fps", "must be 1..1000");
    if (depth_mode != "1mm" && depth_mode != "100um") {
        return ConfigError("depth_mode", "must be 1mm or 100um, got '" + depth_mode + "'");
    }
    if (recover_attempts < 0 || recover_attempts > 10) {
        return ConfigError("recover_attempts", "must be 0..10");
    }
    if (reopen_delay_ms < 0 || reopen_delay_ms > 60'000) {
        return ConfigError("reopen_delay_ms", "must be 0..60000");
    }
    return OkStatus();
}

struct OpenNi2Camera::Impl {
    OpenNi2CameraConfig config;
    std::optional<CameraIntrinsics> override_intrinsics;
    double depth_unit_m = 0.001;

    openni::Device device;
    openni::VideoStream stream;
    bool open = false;
    bool is_file = false;
    std::string uri_in_use;  // the URI the device reported (a USB address for live devices)
    CameraIntrinsics intrinsics;
    openni::PixelFormat format = openni::PIXEL_FORMAT_DEPTH_1_MM;

    std::string Where() const {
        const std::string& u = uri_in_use.empty() ? config.uri : uri_in_use;
        return "openni2 " + (u.empty() ? std::string("(any device)") : u);
    }

    Status OpenOnce();
    void CloseStreams();
    Status SetDepthMode();
    Result<CameraIntrinsics> Intrinsics(const openni::VideoMode& mode) const;
    Status Recover(int attempt);
    Result<DepthImage> ReadOne(std::chrono::milliseconds timeout);
};

Status OpenNi2Camera::Impl::OpenOnce() {
    if (auto st = InitializeOpenNi(); !st) return st;
    const char* uri = config.uri.empty() ? openni::ANY_DEVICE : config.uri.c_str();
    if (device.open(uri) != openni::STATUS_OK) {
        return CameraError(Where() + ": cannot open device: " + LastOpenNiError());
    }
    uri_in_use = device.getDeviceInfo().getUri();
    is_file = device.isFile();
    if (stream.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
        const Error e = CameraError(Where() + ": no depth stream: " + LastOpenNiError());
        device.close();
        return e;
    }
    if (!is_file) {
        if (auto st = SetDepthMode(); !st) {
            CloseStreams();
            return st;
        }
    }
    const openni::VideoMode mode = stream.getVideoMode();
    if (!IsDepthFormat(mode.getPixelFormat())) {
        CloseStreams();
        return CameraError(Where() + ": depth stream has pixel format " +
                           std::to_string(static_cast<int>(mode.getPixelFormat())) +
                           ", not 1 mm or 100 um depth");
    }
    format = mode.getPixelFormat();
    auto k = Intrinsics(mode);
    if (!k) {
        CloseStreams();
        return k.error();
    }
    if (stream.start() != openni::STATUS_OK) {
        const Error e = CameraError(Where() + ": cannot start depth stream: " + LastOpenNiError());
        CloseStreams();
        return e;
    }
    intrinsics = *k;
    open = true;
    spdlog::info("{}: depth {}x{} {} fx={:.1f} fy={:.1f}", Where(), k->width, k->height,
                 format == openni::PIXEL_FORMAT_DEPTH_100_UM ? "100um" : "1mm", k->fx, k->fy);
    return OkStatus();
}

// The configured depth mode, where the device lists it, and no mirroring: it would flip x and
// break the OpenCV camera convention; not every driver has the property, so a refusal is only
// logged.
Status OpenNi2Camera::Impl::SetDepthMode() {
    if (const openni::SensorInfo* info = device.getSensorInfo(openni::SENSOR_DEPTH)) {
        auto mode = ChooseVideoMode(*info, config);
        if (!mode) return CameraError(Where() + ": " + mode.error().message.substr(9));
        const openni::VideoMode current = stream.getVideoMode();
        const bool same = current.getResolutionX() == mode->getResolutionX() &&
                          current.getResolutionY() == mode->getResolutionY() &&
                          current.getPixelFormat() == mode->getPixelFormat() &&
                          current.getFps() == mode->getFps();
        if (!same && stream.setVideoMode(*mode) != openni::STATUS_OK) {
            return CameraError(Where() + ": cannot set the depth mode: " + LastOpenNiError());
        }
    }
    if (stream.setMirroringEnabled(false) != openni::STATUS_OK) {
        spdlog::debug("{}: mirroring cannot be switched off: {}", Where(), LastOpenNiError());
    }
    return OkStatus();
}

// The stream's intrinsics: the config's where it sets them (for the stream's resolution), else
// from the fields of view the stream reports.
Result<CameraIntrinsics> OpenNi2Camera::Impl::Intrinsics(const openni::VideoMode& mode) const {
    CameraIntrinsics k;
    k.width = mode.getResolutionX();
    k.height = mode.getResolutionY();
    k.depth_unit_m = depth_unit_m;
    if (override_intrinsics) {
        if (override_intrinsics->width != k.width || override_intrinsics->height != k.height) {
            return CameraError(Where() + ": camera.intrinsics are for " +
                               std::to_string(override_intrinsics->width) + "x" +
                               std::to_string(override_intrinsics->height) + " but the stream is " +
                               std::to_string(k.width) + "x" + std::to_string(k.height));
        }
        k = *override_intrinsics;  // its size is the stream's: only the depth unit is the device's
        k.depth_unit_m = depth_unit_m;
    } else {
        const double hfov = stream.getHorizontalFieldOfView();
        const double vfov = stream.getVerticalFieldOfView();
        if (!(hfov > 0.0 && hfov < M_PI) || !(vfov > 0.0 && vfov < M_PI)) {
            return CameraError(Where() +
                               ": the stream reports no field of view; set camera.intrinsics "
                               "(fx, fy, cx, cy) in the config");
        }
        k.fx = FocalLengthFromFov(k.width, hfov);
        k.fy = FocalLengthFromFov(k.height, vfov);
        k.cx = (k.width - 1) / 2.0;
        k.cy = (k.height - 1) / 2.0;
    }
    if (auto st = k.Validate("camera"); !st)
        return CameraError(Where() + ": " + st.error().message);
    return k;
}

void OpenNi2Camera::Impl::CloseStreams() {
    if (stream.isValid()) {
        stream.stop();
        // Some drivers' frame threads notice the stop only at their next frame tick (~33 ms);
        // destroying the stream under a running thread crashes them, so give them that tick.
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        stream.destroy();
    }
    if (device.isValid()) device.close();
    open = false;
}

Status OpenNi2Camera::Impl::Recover(int attempt) {
    spdlog::warn("{}: no frames; recovery attempt {} of {}", Where(), attempt,
                 config.recover_attempts);
    const std::optional<UsbAddress> address = UsbAddressFromOpenNiUri(uri_in_use);
    CloseStreams();
    if (config.usb_reset && !is_file) {
        if (auto st = ResetUsbDevice(address); !st) {
            spdlog::warn("{}: {}", Where(), st.error().message);
        } else {
            std::this_thread::sleep_for(std::chrono::milliseconds(config.reopen_delay_ms));
        }
    }
    // After a USB reset the device has a new address: reopen by the configured URI (or any).
    uri_in_use.clear();
    return OpenOnce();
}

Result<DepthImage> OpenNi2Camera::Impl::ReadOne(std::chrono::milliseconds timeout) {
    openni::VideoStream* streams[] = {&stream};
    int ready = -1;
    const int timeout_ms = static_cast<int>(std::max<std::int64_t>(0, timeout.count()));
    if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, timeout_ms) != openni::STATUS_OK) {
        return CameraError(Where() + ": no depth frame within " + std::to_string(timeout_ms) +
                           " ms");
    }
    openni::VideoFrameRef frame;
    if (stream.readFrame(&frame) != openni::STATUS_OK || !frame.isValid()) {
        return CameraError(Where() + ": cannot read frame: " + LastOpenNiError());
    }
    if (frame.getWidth() != intrinsics.width || frame.getHeight() != intrinsics.height) {
        return CameraError(Where() + ": frame is " + std::to_string(frame.getWidth()) + "x" +
                           std::to_string(frame.getHeight()) + ", stream mode is " +
                           std::to_string(intrinsics.width) + "x" +
                           std::to_string(intrinsics.height));
    }
    const double scale = FormatUnitM(frame.getVideoMode().getPixelFormat()) / depth_unit_m;
    const auto* base = static_cast<const std::uint8_t*>(frame.getData());
    const int stride = frame.getStrideInBytes();
    DepthImage image(frame.getWidth(), frame.getHeight());
    for (int y = 0; y < image.height; ++y) {
        const auto* row = reinterpret_cast<const openni::DepthPixel*>(base + y * stride);
        for (int x = 0; x < image.width; ++x) image.at(x, y) = DepthValue(row[x] * scale);
    }
    return image;
}

OpenNi2Camera::OpenNi2Camera(OpenNi2CameraConfig config, std::optional<CameraIntrinsics> intrinsics,
                             double depth_unit_m)
    : impl_(std::make_unique<Impl>()) {
    impl_->config = std::move(config);
    impl_->override_intrinsics = std::move(intrinsics);
    impl_->depth_unit_m = depth_unit_m;
}

OpenNi2Camera::~OpenNi2Camera() { Close(); }

Status OpenNi2Camera::Open() {
    if (impl_->open) return OkStatus();
    if (auto st = impl_->config.Validate(); !st) return CameraError(st.error().message);
    if (!(impl_->depth_unit_m > 0.0)) return CameraError("openni2: depth unit must be positive");
    return impl_->OpenOnce();
}

CameraIntrinsics OpenNi2Camera::Intrinsics() const { return impl_->intrinsics; }

Result<DepthImage> OpenNi2Camera::Grab(std::chrono::milliseconds timeout) {
    if (!impl_->open) return CameraError(impl_->Where() + ": camera is not open");
    auto frame = impl_->ReadOne(timeout);
    for (int attempt = 1; !frame && attempt <= impl_->config.recover_attempts; ++attempt) {
        if (impl_->is_file) break;  // a recording that ran out does not come back by reopening
        if (auto st = impl_->Recover(attempt); !st) {
            spdlog::warn("{}", st.error().message);
            continue;
        }
        frame = impl_->ReadOne(timeout);
    }
    if (!frame && impl_->config.recover_attempts > 0 && !impl_->is_file) {
        return CameraError(frame.error().message + " (after " +
                           std::to_string(impl_->config.recover_attempts) + " recovery attempts)");
    }
    return frame;
}

void OpenNi2Camera::Close() {
    if (impl_) impl_->CloseStreams();
}

std::string OpenNi2Camera::Describe() const { return impl_->Where(); }

std::optional<int> OpenNi2Camera::RecordingFrameCount() const {
    if (!impl_->open || !impl_->is_file) return std::nullopt;
    openni::PlaybackControl* playback = impl_->device.getPlaybackControl();
    if (!playback) return std::nullopt;
    return playback->getNumberOfFrames(impl_->stream);
}

Status RecordOniFile(const OpenNi2CameraConfig& config, const std::string& path, int frames,
                     std::chrono::milliseconds frame_timeout) {
    if (auto st = config.Validate(); !st) return CameraError(st.error().message);
    if (frames <= 0) return CameraError("openni2: frames to record must be positive");
    if (auto st = InitializeOpenNi(); !st) return st;
    const std::string where = "openni2 " + (config.uri.empty() ? "(any device)" : config.uri);
    openni::Device device;
    const char* uri = config.uri.empty() ? openni::ANY_DEVICE : config.uri.c_str();
    if (device.open(uri) != openni::STATUS_OK) {
        return CameraError(where + ": cannot open device: " + LastOpenNiError());
    }
    openni::VideoStream stream;
    openni::Recorder recorder;
    // Everything below releases in reverse order on every return path.
    auto finish = [&](Status status) -> Status {
        if (recorder.isValid()) recorder.stop();
        if (stream.isValid()) {
            stream.stop();
            std::this_thread::sleep_for(std::chrono::milliseconds(100));  // see CloseStreams
        }
        if (recorder.isValid()) recorder.destroy();
        if (stream.isValid()) stream.destroy();
        device.close();
        return status;
    };
    if (stream.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
        return finish(CameraError(where + ": no depth stream: " + LastOpenNiError()));
    }
    if (recorder.create(path.c_str()) != openni::STATUS_OK) {
        return finish(CameraError(where + ": cannot create " + path + ": " + LastOpenNiError()));
    }
    if (recorder.attach(stream, false) != openni::STATUS_OK) {
        return finish(
            CameraError(where + ": cannot record the depth stream: " + LastOpenNiError()));
    }
    // The recorder starts first, so every frame the stream delivers is in the file.
    if (recorder.start() != openni::STATUS_OK || stream.start() != openni::STATUS_OK) {
        return finish(CameraError(where + ": cannot start recording: " + LastOpenNiError()));
    }
    for (int i = 0; i < frames; ++i) {
        openni::VideoStream* streams[] = {&stream};
        int ready = -1;
        if (openni::OpenNI::waitForAnyStream(
                streams, 1, &ready, static_cast<int>(frame_timeout.count())) != openni::STATUS_OK) {
            return finish(CameraError(where + ": no depth frame within " +
                                      std::to_string(frame_timeout.count()) + " ms after " +
                                      std::to_string(i) + " frames"));
        }
        openni::VideoFrameRef frame;
        if (stream.readFrame(&frame) != openni::STATUS_OK) {
            return finish(CameraError(where + ": cannot read frame: " + LastOpenNiError()));
        }
    }
    return finish(OkStatus());
}

}  // namespace boxd
