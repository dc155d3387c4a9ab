#pragma once
// The Kinect v1 (Xbox 360 and Kinect for Windows) depth camera through libfreenect, and Kinect
// dump folders through Debian's fakenect, the drop-in libfreenect that replays them.
//
// Depth: in millimetres through the device's own calibration (libfreenect's FREENECT_DEPTH_MM,
// from the zero-plane data in the camera's EEPROM) where the library offers it, else the raw
// 11-bit disparity converted with the published Kinect v1 conversion
// (pipeline/core/kinect_disparity.h). fakenect offers only the raw stream.
//
// Frames are read on demand: Grab runs libfreenect's event loop until the next depth frame, so
// frames come in the order the device (or the dump) delivers them, and while nobody grabs the
// device's frames are dropped by the library. A replay thus gives the k-th recorded frame to the
// k-th Grab, whatever the turntable's pace.

#include <memory>
#include <optional>
#include <string>

#include "drivers/depth_camera.h"

namespace boxd {

// The `camera.freenect:` section.
struct FreenectCameraConfig {
    int index = 0;       // which Kinect (0 = the first), unless `serial` is set
    std::string serial;  // the camera's serial number ("A00366A10291104A"), as `boxd devices`
    std::string depth_format = "auto";  // auto | mm | 11bit (see above; auto = mm if offered)
    std::optional<double> tilt_deg;     // motor angle held from Open (-27..27); none: left alone
    bool led = true;  // the LED shows the station's state (green idle, blinking green while
                      // measuring, red after a fault)
    // When frames stop: how many times to close, reset through libusb (when `usb_reset`) and
    // reopen the device before Grab gives up.
    int recover_attempts = 2;
    bool usb_reset = true;
    int reopen_delay_ms = 2000;  // wait after closing (and a reset) for the device to return

    // Returns an error naming the first invalid field ("camera.freenect.<field>: ..."), or Ok.
    Status Validate() const;
};

class FreenectCamera : public DepthCamera {
public:
    // `intrinsics`: fx/fy/cx/cy to use instead of the device's (640 x 480); `depth_unit_m`:
    // unit of the frames Grab returns.
    FreenectCamera(FreenectCameraConfig config, std::optional<CameraIntrinsics> intrinsics,
                   double depth_unit_m);
    ~FreenectCamera() override;

    Status Open() override;
    CameraIntrinsics Intrinsics() const override;
    Result<DepthImage> Grab(std::chrono::milliseconds timeout) override;
    void Close() override;
    std::string SourceName() const override { return "freenect"; }
    std::string Describe() const override;
    std::optional<CameraTilt> Tilt() override;
    void Indicate(StationLight light) override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The Kinect v1 depth camera's intrinsics at 640 x 480 from its zero-plane data: the sensor's
// 1280 x 1024 image cropped to 1280 x 960 and halved, so f = reference_distance / (2 x
// reference_pixel_size) and the principal point (320, 240) (libfreenect's camera_to_world). The
// defaults are libfreenect's typical device values (120 mm, 0.1042 mm: f = 575.8 px).
CameraIntrinsics KinectIntrinsics(double reference_distance_mm = 120.0,
                                  double reference_pixel_size_mm = 0.1042);

}  // namespace boxd
