// The OpenNI2 camera through the real libOpenNI2: its "Dummy" device driver (a synthetic
// 320x240, 1 mm depth stream shipped with OpenNI2), .oni recordings made with
// openni::Recorder and read back through the OniFile driver, and missing devices.
#include "drivers/openni2_camera.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "drivers/usb_devices.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using std::chrono::milliseconds;

// The Dummy driver reports no field of view, so its intrinsics come from the config.
CameraIntrinsics DummyIntrinsics() {
    CameraIntrinsics k;
    k.width = 320;
    k.height = 240;
    k.fx = k.fy = 285.0;
    k.cx = 159.5;
    k.cy = 119.5;
    return k;
}

OpenNi2CameraConfig DummyConfig() {
    OpenNi2CameraConfig c;
    c.uri = "Dummy";
    c.width = 320;
    c.height = 240;
    c.recover_attempts = 0;
    return c;
}

TEST(OpenNi2Camera, MissingRecordingIsACameraErrorNamingIt) {
    OpenNi2CameraConfig c;
    c.uri = "/nonexistent/boxd/recording.oni";
    OpenNi2Camera camera(c, std::nullopt, 0.001);
    const Status st = camera.Open();
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kCameraError);
    EXPECT_NE(st.error().message.find("/nonexistent/boxd/recording.oni"), std::string::npos);
    const auto frame = camera.Grab(milliseconds(10));
    ASSERT_FALSE(frame.ok());
    EXPECT_EQ(frame.error().code, ErrorCode::kCameraError);
}

TEST(OpenNi2Camera, MissingUsbDeviceIsACameraError) {
    OpenNi2CameraConfig c;
    c.uri = "1d27/0601@250/127";  // no such bus here
    OpenNi2Camera camera(c, std::nullopt, 0.001);
    const Status st = camera.Open();
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kCameraError);
    EXPECT_NE(st.error().message.find("cannot open device"), std::string::npos);
}

TEST(OpenNi2Camera, DummyDeviceDeliversMillimetreFrames) {
    OpenNi2Camera camera(DummyConfig(), DummyIntrinsics(), 0.001);
    ASSERT_TRUE(camera.Open().ok());
    const CameraIntrinsics k = camera.Intrinsics();
    EXPECT_EQ(k.width, 320);
    EXPECT_EQ(k.height, 240);
    EXPECT_DOUBLE_EQ(k.fx, 285.0);
    EXPECT_DOUBLE_EQ(k.depth_unit_m, 0.001);
    for (int i = 0; i < 3; ++i) {
        auto frame = camera.Grab(milliseconds(2000));
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        ASSERT_EQ(frame->width, 320);
        ASSERT_EQ(frame->height, 240);
        // The Dummy driver paints its first row at 2000 mm.
        EXPECT_EQ(frame->at(0, 0), 2000);
        EXPECT_EQ(frame->at(319, 0), 2000);
    }
    camera.Close();
}

TEST(OpenNi2Camera, ConvertsToTheSessionDepthUnit) {
    OpenNi2Camera camera(DummyConfig(), DummyIntrinsics(), 0.0005);
    ASSERT_TRUE(camera.Open().ok());
    auto frame = camera.Grab(milliseconds(2000));
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    EXPECT_EQ(frame->at(10, 0), 4000);  // 2.000 m in 0.5 mm units
    EXPECT_DOUBLE_EQ(camera.Intrinsics().depth_unit_m, 0.0005);
}

TEST(OpenNi2Camera, StreamWithoutFieldOfViewNeedsConfiguredIntrinsics) {
    OpenNi2Camera camera(DummyConfig(), std::nullopt, 0.001);
    const Status st = camera.Open();
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kCameraError);
    EXPECT_NE(st.error().message.find("camera.intrinsics"), std::string::npos);
}

TEST(OpenNi2Camera, UnsupportedModeListsTheOfferedModes) {
    OpenNi2CameraConfig c = DummyConfig();
    c.width = 640;
    c.height = 480;
    OpenNi2Camera camera(c, std::nullopt, 0.001);
    const Status st = camera.Open();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().message.find("320x240"), std::string::npos) << st.error().message;
}

TEST(OpenNi2Camera, IntrinsicsForAnotherSizeAreRefused) {
    CameraIntrinsics k;  // 640x480
    OpenNi2Camera camera(DummyConfig(), k, 0.001);
    const Status st = camera.Open();
    ASSERT_FALSE(st.ok());
    EXPECT_NE(st.error().message.find("640x480"), std::string::npos) << st.error().message;
}

TEST(OpenNi2Camera, RecordingOfTheDummyDeviceReadsBack) {
    test::TempDir dir;
    const std::string path = (dir / "dummy.oni").string();
    constexpr int kFrames = 8;
    const Status recorded = RecordOniFile(DummyConfig(), path, kFrames, milliseconds(2000));
    ASSERT_TRUE(recorded.ok()) << recorded.error().message;
    ASSERT_TRUE(std::filesystem::exists(path));

    OpenNi2CameraConfig c;
    c.uri = path;  // an .oni path opens through OpenNI2's OniFile driver
    OpenNi2Camera camera(c, DummyIntrinsics(), 0.001);
    const Status opened = camera.Open();
    ASSERT_TRUE(opened.ok()) << opened.error().message;
    EXPECT_EQ(camera.Intrinsics().width, 320);
    EXPECT_EQ(camera.Intrinsics().height, 240);
    EXPECT_DOUBLE_EQ(camera.Intrinsics().fx, 285.0);
    const auto count = camera.RecordingFrameCount();
    ASSERT_TRUE(count.has_value());
    // The frames read while recording are in the file, give or take the one in flight when
    // the recorder's listener starts or stops.
    EXPECT_GE(*count, kFrames - 1);
    EXPECT_LE(*count, kFrames + 2);

    // Playback must never hang: a frame or a CAMERA_ERROR within the timeout. (Debian's
    // OniFile player may not deliver frames at all; see docs/station.md.)
    const auto start = std::chrono::steady_clock::now();
    auto frame = camera.Grab(milliseconds(1000));
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
    if (frame.ok()) {
        EXPECT_EQ(frame->width, 320);
        EXPECT_EQ(frame->at(5, 0), 2000);
    } else {
        EXPECT_EQ(frame.error().code, ErrorCode::kCameraError);
    }
    camera.Close();
}

TEST(UsbDevices, KnownDepthCameraIds) {
    // Each with the camera.driver that drives it: Debian's OpenNI2 has no Kinect driver.
    const auto driver = [](std::uint16_t vendor, std::uint16_t product) {
        const auto known = FindDepthCamera(vendor, product);
        return known ? known->driver : std::string("none");
    };
    EXPECT_EQ(driver(0x045e, 0x02ae), "freenect");  // Kinect v1 camera
    EXPECT_EQ(driver(0x045e, 0x02bf), "freenect");  // Kinect for Windows camera
    EXPECT_EQ(driver(0x045e, 0x02b0), "none");      // Kinect v1 motor
    EXPECT_EQ(driver(0x045e, 0x0040), "none");      // a Microsoft mouse
    EXPECT_EQ(driver(0x1d27, 0x0601), "openni2");   // Xtion Pro Live
    EXPECT_EQ(driver(0x2bc5, 0x0401), "openni2");   // Orbbec Astra
    EXPECT_EQ(driver(0x0b05, 0x1234), "none");      // ASUS, not a camera
    EXPECT_EQ(UsbIdString(0x045e, 0x02ae), "045e:02ae");
}

TEST(UsbDevices, OpenNiUriCarriesTheUsbAddress) {
    const auto a = UsbAddressFromOpenNiUri("1d27/0601@3/12");
    ASSERT_TRUE(a.has_value());
    EXPECT_EQ(a->bus, 3);
    EXPECT_EQ(a->address, 12);
    EXPECT_FALSE(UsbAddressFromOpenNiUri("/tmp/recording.oni").has_value());
    EXPECT_FALSE(UsbAddressFromOpenNiUri("Dummy").has_value());
}

TEST(UsbDevices, ResettingAMissingDeviceIsACameraError) {
    const Status st = ResetUsbDevice(UsbAddress{250, 127});
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, ErrorCode::kCameraError);
}

}  // namespace
}  // namespace boxd
