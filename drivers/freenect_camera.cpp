#include "drivers/freenect_camera.h"

#include <dlfcn.h>
#include <libfreenect.h>
#include <libfreenect_registration.h>
#include <libusb.h>
#include <spdlog/spdlog.h>
#include <sys/time.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <thread>
#include <vector>

#include "drivers/freenect_dump.h"
#include "drivers/usb_devices.h"

namespace boxd {

// freenect_dump.cpp writes accelerometer records of this size.
static_assert(sizeof(freenect_raw_tilt_state) == 12, "libfreenect's tilt state layout changed");

namespace {

using Clock = std::chrono::steady_clock;

// Whether the libfreenect this process runs on is fakenect, Debian's replay library (it sits in
// the library folder's fakenect/ and is chosen with LD_LIBRARY_PATH).
bool RunningOnFakenect() {
    Dl_info info{};
    void* init = dlsym(RTLD_DEFAULT, "freenect_init");
    if (!init || !dladdr(init, &info) || !info.dli_fname) return false;
    return std::string(info.dli_fname).find("/fakenect/") != std::string::npos;
}

void LogFromLibrary(freenect_context*, freenect_loglevel level, const char* message) {
    std::string text = message ? message : "";
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    if (level <= FREENECT_LOG_ERROR) {
        spdlog::warn("libfreenect: {}", text);
    } else {
        spdlog::debug("libfreenect: {}", text);
    }
}

freenect_led_options LedOf(StationLight light) {
    switch (light) {
        case StationLight::kIdle:
            return LED_GREEN;
        case StationLight::kMeasuring:
            return LED_BLINK_GREEN;
        case StationLight::kFault:
            return LED_RED;
        case StationLight::kOff:
            break;
    }
    return LED_OFF;
}

// The device's zero-plane data, through freenect_copy_registration where the library has it
// (looked up at run time: fakenect lacks it, and boxd must start on both).
std::optional<CameraIntrinsics> DeviceIntrinsics(freenect_device* dev) {
    using Copy = freenect_registration (*)(freenect_device*);
    using Destroy = int (*)(freenect_registration*);
    auto copy = reinterpret_cast<Copy>(dlsym(RTLD_DEFAULT, "freenect_copy_registration"));
    auto destroy = reinterpret_cast<Destroy>(dlsym(RTLD_DEFAULT, "freenect_destroy_registration"));
    if (!copy || !destroy) return std::nullopt;
    freenect_registration reg = copy(dev);
    const double distance = reg.zero_plane_info.reference_distance;
    const double pixel = reg.zero_plane_info.reference_pixel_size;
    destroy(&reg);
    if (!(distance > 10.0 && distance < 1000.0) || !(pixel > 0.001 && pixel < 1.0)) {
        return std::nullopt;
    }
    return KinectIntrinsics(distance, pixel);
}

}  // namespace

struct FreenectCamera::Impl {
    FreenectCameraConfig config;
    std::optional<CameraIntrinsics> override_intrinsics;
    double depth_unit_m = 0.001;

    std::mutex mutex;  // held around every libfreenect call
    freenect_context* ctx = nullptr;
    freenect_device* dev = nullptr;
    bool open = false;
    bool replay = false;  // fakenect replaying the dump in FAKENECT_PATH
    std::string dump;     // that dump
    freenect_depth_format format = FREENECT_DEPTH_11BIT;
    CameraIntrinsics intrinsics;
    std::vector<std::uint16_t> frame;  // the last depth frame the library delivered
    bool fresh = false;                // set by the depth callback
    long frames = 0;                   // frames delivered since Open
    std::mutex tilt_mutex;             // guards `tilt`, read by status pages
    std::optional<CameraTilt> tilt;    // the last accelerometer reading
    std::atomic<int> light{-1};        // a StationLight waiting to be shown

    std::string Where() const {
        if (replay) return "freenect replay " + dump;
        return "freenect " +
               (config.serial.empty() ? "#" + std::to_string(config.index) : config.serial);
    }

    static void OnDepth(freenect_device* dev, void* data, std::uint32_t) {
        auto* self = static_cast<Impl*>(freenect_get_user(dev));
        const auto* values = static_cast<const std::uint16_t*>(data);
        self->frame.assign(values, values + kKinectDepthWidth * kKinectDepthHeight);
        self->fresh = true;
    }

    Status OpenOnce();
    Status StartContext();
    Status OpenDevice(int subdevices);
    Result<freenect_frame_mode> ChooseMode() const;
    void CloseDevice();
    Result<DepthImage> ReadOne(std::chrono::milliseconds timeout);
    DepthImage Convert(const std::vector<std::uint16_t>& values) const;
    void ReadTilt();
    void ShowLight();
};

Result<freenect_frame_mode> FreenectCamera::Impl::ChooseMode() const {
    std::optional<freenect_frame_mode> mm, raw;
    for (int i = 0; i < freenect_get_depth_mode_count(); ++i) {
        const freenect_frame_mode m = freenect_get_depth_mode(i);
        if (!m.is_valid || m.resolution != FREENECT_RESOLUTION_MEDIUM) continue;
        if (m.depth_format == FREENECT_DEPTH_MM) mm = m;
        if (m.depth_format == FREENECT_DEPTH_11BIT) raw = m;
    }
    if (config.depth_format != "11bit" && mm) return *mm;
    if (config.depth_format == "mm") {
        return CameraError(Where() + ": this libfreenect offers no millimetre depth (a fakenect " +
                           "replay streams raw 11-bit only); set camera.freenect.depth_format to "
                           "auto or 11bit");
    }
    if (!raw) return CameraError(Where() + ": libfreenect offers no 640 x 480 11-bit depth mode");
    return *raw;
}

Status FreenectCamera::Impl::StartContext() {
    if (freenect_init(&ctx, nullptr) < 0) {
        ctx = nullptr;
        return CameraError(Where() + ": libfreenect cannot start (libusb)");
    }
    freenect_set_log_level(ctx, FREENECT_LOG_WARNING);
    freenect_set_log_callback(ctx, &LogFromLibrary);
    return OkStatus();
}

Status FreenectCamera::Impl::OpenDevice(int subdevices) {
    freenect_select_subdevices(ctx, static_cast<freenect_device_flags>(subdevices));
    const int count = freenect_num_devices(ctx);
    if (count <= 0) {
        return CameraError(Where() +
                           ": no Kinect found (`boxd devices` lists the USB cameras; "
                           "is the Kinect's power supply plugged in?)");
    }
    if (config.serial.empty() && config.index >= count) {
        return CameraError(Where() + ": there is no Kinect #" + std::to_string(config.index) +
                           " (" + std::to_string(count) + " attached; the first is #0)");
    }
    const int rc = config.serial.empty()
                       ? freenect_open_device(ctx, &dev, config.index)
                       : freenect_open_device_by_camera_serial(ctx, &dev, config.serial.c_str());
    if (rc < 0 || !dev) {
        dev = nullptr;
        return CameraError(Where() +
                           ": cannot open the device (is another program using it? "
                           "the boxd user needs the plugdev group)");
    }
    auto mode = ChooseMode();
    if (!mode) return mode.error();
    if (freenect_set_depth_mode(dev, *mode) < 0) {
        return CameraError(Where() + ": cannot set the 640 x 480 depth mode");
    }
    format = mode->depth_format;
    freenect_set_user(dev, this);
    freenect_set_depth_callback(dev, &Impl::OnDepth);
    if (freenect_start_depth(dev) < 0)
        return CameraError(Where() + ": cannot start the depth stream");
    if (config.tilt_deg && freenect_set_tilt_degs(dev, *config.tilt_deg) < 0) {
        spdlog::warn("{}: the tilt motor did not take {} degrees", Where(), *config.tilt_deg);
    }
    return OkStatus();
}

Status FreenectCamera::Impl::OpenOnce() {
    replay = RunningOnFakenect();
    if (replay) {
        // fakenect ends the process on a dump it cannot read: check it first.
        const char* path = std::getenv("FAKENECT_PATH");
        if (!path || !*path) {
            return CameraError(
                "freenect: the fakenect replay library is loaded but FAKENECT_PATH "
                "names no dump folder");
        }
        dump = path;
        if (auto index = CheckDump(dump); !index) return index.error();
    }
    std::lock_guard lock(mutex);
    // The motor device carries the accelerometer, the LED and the tilt: asked for always, and
    // left out when the device will not open with it (not every Kinect model's motor is one
    // this libfreenect drives).
    Status st = StartContext();
    if (st) st = OpenDevice(FREENECT_DEVICE_CAMERA | FREENECT_DEVICE_MOTOR);
    if (!st && ctx && !replay) {
        const std::string with_motor = st.error().message;
        CloseDevice();
        st = StartContext();
        if (st) st = OpenDevice(FREENECT_DEVICE_CAMERA);
        if (st)
            spdlog::warn("{}; opened without its motor: no LED, tilt nor accelerometer",
                         with_motor);
    }
    if (!st) {
        CloseDevice();
        return st;
    }
    intrinsics = override_intrinsics ? *override_intrinsics
                                     : DeviceIntrinsics(dev).value_or(KinectIntrinsics());
    intrinsics.depth_unit_m = depth_unit_m;
    open = true;
    frames = 0;
    spdlog::info("{}: depth 640x480 {} fx={:.1f} cx={:.1f} cy={:.1f}", Where(),
                 format == FREENECT_DEPTH_MM ? "mm (device calibration)" : "11-bit disparity",
                 intrinsics.fx, intrinsics.cx, intrinsics.cy);
    return OkStatus();
}

void FreenectCamera::Impl::CloseDevice() {
    if (dev) {
        freenect_stop_depth(dev);
        freenect_close_device(dev);
        dev = nullptr;
    }
    if (ctx) {
        freenect_shutdown(ctx);
        ctx = nullptr;
    }
    open = false;
}

DepthImage FreenectCamera::Impl::Convert(const std::vector<std::uint16_t>& values) const {
    DepthImage image(kKinectDepthWidth, kKinectDepthHeight);
    if (format == FREENECT_DEPTH_MM) {
        const double scale = 0.001 / depth_unit_m;
        for (std::size_t i = 0; i < values.size(); ++i)
            image.pixels[i] = DepthValue(values[i] * scale);
    } else {
        image.pixels = RawDisparityToDepth(values, depth_unit_m);
    }
    return image;
}

Result<DepthImage> FreenectCamera::Impl::ReadOne(std::chrono::milliseconds timeout) {
    const Clock::time_point deadline = Clock::now() + timeout;
    std::vector<std::uint16_t> got;
    {
        std::lock_guard lock(mutex);
        fresh = false;
    }
    while (got.empty()) {
        const auto left =
            std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now());
        if (left.count() <= 0) {
            return CameraError(Where() + ": no depth frame within " +
                               std::to_string(timeout.count()) + " ms");
        }
        timeval tv{0, static_cast<suseconds_t>(std::min<long long>(left.count(), 100'000))};
        int rc = 0;
        {
            // The depth callback runs inside whichever libfreenect call handles USB events:
            // the frame is taken under the same lock.
            std::lock_guard lock(mutex);
            if (!ctx) return CameraError(Where() + ": camera is not open");
            rc = freenect_process_events_timeout(ctx, &tv);
            if (fresh) got.swap(frame);
        }
        if (rc == LIBUSB_ERROR_INTERRUPTED) continue;  // a signal, not the device
        if (rc < 0 && replay) {
            return CameraError(Where() + ": the recording ended after " + std::to_string(frames) +
                               " depth frames");
        }
        if (rc < 0) {
            return CameraError(Where() + ": the USB link failed (libusb " + std::to_string(rc) +
                               ")");
        }
    }
    ++frames;
    return Convert(got);
}

void FreenectCamera::Impl::ReadTilt() {
    if (!dev) return;
    freenect_update_tilt_state(dev);
    freenect_raw_tilt_state* state = freenect_get_tilt_state(dev);
    if (!state) return;
    CameraTilt t;
    freenect_get_mks_accel(state, &t.accel_mps2[0], &t.accel_mps2[1], &t.accel_mps2[2]);
    const double g = std::hypot(t.accel_mps2[0], t.accel_mps2[1], t.accel_mps2[2]);
    if (!(g > 1.0)) return;  // no reading (a dump without accelerometer records)
    constexpr double kDeg = 180.0 / M_PI;
    // Level, the Kinect's y axis holds gravity; pitching the optical axis (z) moves it into z.
    t.tilt_deg = std::asin(std::clamp(t.accel_mps2[2] / g, -1.0, 1.0)) * kDeg;
    t.roll_deg = std::atan2(t.accel_mps2[0], t.accel_mps2[1]) * kDeg;
    t.motor_deg = freenect_get_tilt_degs(state);
    std::lock_guard lock(tilt_mutex);
    tilt = t;
}

void FreenectCamera::Impl::ShowLight() {
    if (!dev || !config.led) return;  // a closed camera shows it once open
    const int pending = light.exchange(-1);
    if (pending < 0) return;
    freenect_set_led(dev, LedOf(static_cast<StationLight>(pending)));
}

FreenectCamera::FreenectCamera(FreenectCameraConfig config,
                               std::optional<CameraIntrinsics> intrinsics, double depth_unit_m)
    : impl_(std::make_unique<Impl>()) {
    impl_->config = std::move(config);
    impl_->override_intrinsics = std::move(intrinsics);
    impl_->depth_unit_m = depth_unit_m;
}

FreenectCamera::~FreenectCamera() { Close(); }

Status FreenectCamera::Open() {
    if (impl_->open) return OkStatus();
    if (auto st = impl_->config.Validate(); !st) return CameraError(st.error().message);
    if (!(impl_->depth_unit_m > 0.0)) return CameraError("freenect: depth unit must be positive");
    if (impl_->override_intrinsics && (impl_->override_intrinsics->width != kKinectDepthWidth ||
                                       impl_->override_intrinsics->height != kKinectDepthHeight)) {
        return CameraError("freenect: camera.intrinsics must be for 640 x 480");
    }
    if (auto st = impl_->OpenOnce(); !st) return st;
    std::lock_guard lock(impl_->mutex);
    impl_->ReadTilt();
    impl_->ShowLight();
    return OkStatus();
}

CameraIntrinsics FreenectCamera::Intrinsics() const { return impl_->intrinsics; }

Result<DepthImage> FreenectCamera::Grab(std::chrono::milliseconds timeout) {
    if (!impl_->open) return CameraError(impl_->Where() + ": camera is not open");
    auto frame = impl_->ReadOne(timeout);
    // A replay that ended does not come back by reopening; a live device may.
    const FreenectCameraConfig& c = impl_->config;
    for (int attempt = 1; !frame && !impl_->replay && attempt <= c.recover_attempts; ++attempt) {
        spdlog::warn("{}; reopening the device ({} of {})", frame.error().message, attempt,
                     c.recover_attempts);
        {
            std::lock_guard lock(impl_->mutex);
            impl_->CloseDevice();
        }
        Status reset = c.usb_reset ? ResetCameraOf("freenect", c.serial, c.index) : OkStatus();
        if (!reset) spdlog::warn("{}: {}", impl_->Where(), reset.error().message);
        std::this_thread::sleep_for(std::chrono::milliseconds(c.reopen_delay_ms));
        Status opened = impl_->OpenOnce();
        frame = opened ? impl_->ReadOne(timeout) : Result<DepthImage>(opened.error());
    }
    std::lock_guard lock(impl_->mutex);
    if (frame) impl_->ReadTilt();
    impl_->ShowLight();
    return frame;
}

void FreenectCamera::Close() {
    if (!impl_) return;
    std::lock_guard lock(impl_->mutex);
    impl_->CloseDevice();
}

std::string FreenectCamera::Describe() const { return impl_->Where(); }

std::optional<CameraTilt> FreenectCamera::Tilt() {
    // Read with every frame and at Open (a USB transfer of its own, never on a status page's
    // thread): between measurements, the last one's reading.
    std::lock_guard lock(impl_->tilt_mutex);
    return impl_->tilt;
}

void FreenectCamera::Indicate(StationLight light) {
    impl_->light = static_cast<int>(light);
    std::lock_guard lock(impl_->mutex);
    impl_->ShowLight();  // kept for Open when the camera is closed
}

}  // namespace boxd
