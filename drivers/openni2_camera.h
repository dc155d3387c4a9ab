#pragma once
// The OpenNI2 depth camera: PrimeSense-class structured-light sensors (Kinect v1, ASUS Xtion,
// Orbbec) and .oni recordings, through libOpenNI2 and its drivers.

#include <memory>
#include <optional>
#include <string>

#include "drivers/depth_camera.h"

namespace boxd {

// The `camera.openni2:` section.
struct OpenNi2CameraConfig {
    // Device URI ("1d27/0601@1/5"), an .oni recording path, or "" for the first device found.
    std::string uri;
    int width = 640;  // depth stream resolution (ignored for recordings, which keep theirs)
    int height = 480;
    int fps = 30;
    std::string depth_mode = "1mm";  // "1mm" or "100um": the sensor's pixel format
    // When the stream stops delivering frames: how many times to close, reset through libusb
    // (when `usb_reset`) and reopen before Grab gives up.
    int recover_attempts = 2;
    bool usb_reset = true;
    int reopen_delay_ms = 2000;  // wait after a reset for the device to re-enumerate

    // Returns an error naming the first invalid field ("camera.openni2.<field>: ..."), or Ok.
    Status Validate() const;
};

class OpenNi2Camera : public DepthCamera {
public:
    // `intrinsics`: fx/fy/cx/cy to use instead of the ones derived from the stream's field of
    // view (its width/height must match the stream). `depth_unit_m`: unit of the frames Grab
    // returns (the sensor's 1 mm or 100 µm values are converted to it).
    OpenNi2Camera(OpenNi2CameraConfig config, std::optional<CameraIntrinsics> intrinsics,
                  double depth_unit_m);
    ~OpenNi2Camera() override;

    Status Open() override;
    CameraIntrinsics Intrinsics() const override;
    Result<DepthImage> Grab(std::chrono::milliseconds timeout) override;
    void Close() override;
    std::string SourceName() const override { return "openni2"; }
    std::string Describe() const override;

    // Returns the number of frames of an opened .oni recording, or nothing for a live device.
    std::optional<int> RecordingFrameCount() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Returns the pinhole focal length in pixels of an image `size_px` wide (or high) that spans the
// field of view `fov_rad`: f = size / 2 / tan(fov / 2).
double FocalLengthFromFov(int size_px, double fov_rad);

}  // namespace boxd

namespace boxd {

// Records `frames` depth frames of the device `config.uri` names into the OpenNI .oni file
// `path` with openni::Recorder (lossless), for support cases and regression recordings.
// CAMERA_ERROR when the device cannot be opened or delivers too few frames.
Status RecordOniFile(const OpenNi2CameraConfig& config, const std::string& path, int frames,
                     std::chrono::milliseconds frame_timeout);

}  // namespace boxd
