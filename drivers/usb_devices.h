#pragma once
// Depth cameras on the USB bus, seen through libusb: listing them (`boxd devices`) and resetting
// one that stopped delivering frames (the OpenNI2 driver's recovery step).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/core/result.h"

namespace boxd {

// A USB vendor (and optionally product) that boxd knows as an OpenNI2-class depth camera.
struct KnownDepthCamera {
    std::uint16_t vendor_id = 0;
    std::optional<std::uint16_t> product_id;  // empty: every product of the vendor
    std::string name;
    std::string driver;  // the camera.driver that drives it: openni2 or freenect
};

// Returns the table of known depth cameras: PrimeSense (also ASUS Xtion, which ships with the
// PrimeSense vendor id) and Orbbec through OpenNI2, the Microsoft Kinect v1 camera interfaces
// through libfreenect (Debian's OpenNI2 has no Kinect driver).
const std::vector<KnownDepthCamera>& KnownDepthCameras();

// Returns the known camera with these ids, or nothing when it is not one.
std::optional<KnownDepthCamera> FindDepthCamera(std::uint16_t vendor_id, std::uint16_t product_id);

// One attached USB device.
struct UsbDeviceInfo {
    std::uint16_t vendor_id = 0;
    std::uint16_t product_id = 0;
    std::string name;       // known camera name, or "" for other devices
    std::string driver;     // the camera.driver for it, or "" for other devices
    std::string serial;     // its serial number string, or "" when it has none or no access
    int bus = 0;            // bus number
    int address = 0;        // device address on the bus (changes on re-enumeration)
    std::string port_path;  // "<bus>-<port>.<port>...", stable while the cable stays put
};

// Returns the attached depth cameras (or every USB device with `all`); an empty list when none
// are attached; CAMERA_ERROR when libusb cannot be initialised.
Result<std::vector<UsbDeviceInfo>> ListUsbDevices(bool all = false);

// Bus and address of a USB device.
struct UsbAddress {
    int bus = 0;
    int address = 0;
};

// Returns the bus/address in an OpenNI2 device URI such as "1d27/0601@1/5", or nothing when the
// URI does not carry one (files, other drivers).
std::optional<UsbAddress> UsbAddressFromOpenNiUri(const std::string& uri);

// Resets the USB device at `address` (the device re-enumerates, like unplugging it); resets the
// first attached known depth camera when `address` is empty. CAMERA_ERROR when there is no such
// device or the reset fails.
Status ResetUsbDevice(const std::optional<UsbAddress>& address);

// Resets the `index`-th attached camera that `driver` drives (in the bus's order, as libfreenect
// counts them), or the one whose serial number is `serial` when that is set (the freenect
// driver's recovery step). CAMERA_ERROR when there is none or the reset fails.
Status ResetCameraOf(const std::string& driver, const std::string& serial, int index);

// Returns "045e:02ae" for the ids.
std::string UsbIdString(std::uint16_t vendor_id, std::uint16_t product_id);

}  // namespace boxd
