// Depth cameras on the USB bus through libusb-1.0.
#include "drivers/usb_devices.h"

#include <libusb.h>

#include <cstdio>
#include <memory>
#include <regex>

#include "drivers/depth_camera.h"

namespace boxd {

namespace {

// A libusb context that is released on every return path.
struct ContextDeleter {
    void operator()(libusb_context* ctx) const { libusb_exit(ctx); }
};
using ContextPtr = std::unique_ptr<libusb_context, ContextDeleter>;

Result<ContextPtr> InitLibusb() {
    libusb_context* ctx = nullptr;
    const int rc = libusb_init(&ctx);
    if (rc != 0) {
        return CameraError(std::string("libusb: cannot initialise: ") + libusb_error_name(rc));
    }
    return ContextPtr(ctx);
}

// The device list of a context, freed on every return path.
class DeviceList {
public:
    explicit DeviceList(libusb_context* ctx) {
        const ssize_t n = libusb_get_device_list(ctx, &list_);
        count_ = n < 0 ? 0 : static_cast<std::size_t>(n);
        error_ = n < 0 ? static_cast<int>(n) : 0;
    }
    ~DeviceList() {
        if (list_) libusb_free_device_list(list_, 1);
    }
    DeviceList(const DeviceList&) = delete;
    DeviceList& operator=(const DeviceList&) = delete;
    std::size_t size() const { return count_; }
    libusb_device* operator[](std::size_t i) const { return list_[i]; }
    int error() const { return error_; }

private:
    libusb_device** list_ = nullptr;
    std::size_t count_ = 0;
    int error_ = 0;
};

std::string PortPath(libusb_device* dev) {
    std::uint8_t ports[8];
    const int n = libusb_get_port_numbers(dev, ports, sizeof(ports));
    std::string path = std::to_string(libusb_get_bus_number(dev));
    for (int i = 0; i < n; ++i) {
        path.push_back(i == 0 ? '-' : '.');
        path.append(std::to_string(ports[i]));
    }
    return path;
}

// The device's serial number string (what camera.freenect.serial names), or "" when it has
// none or the device cannot be opened (no access: the udev rule's plugdev group).
std::string SerialNumber(libusb_device* dev, std::uint8_t index) {
    if (index == 0) return "";
    libusb_device_handle* handle = nullptr;
    if (libusb_open(dev, &handle) != 0) return "";
    unsigned char text[128] = {};
    const int n = libusb_get_string_descriptor_ascii(handle, index, text, sizeof(text));
    libusb_close(handle);
    return n > 0 ? std::string(reinterpret_cast<char*>(text), static_cast<std::size_t>(n)) : "";
}

}  // namespace

const std::vector<KnownDepthCamera>& KnownDepthCameras() {
    // Vendor ids from the USB-IF list and the udev rules OpenNI2 ships
    // (60-libopenni2-0.rules). ASUS Xtion sensors enumerate with the PrimeSense vendor id
    // (0x1d27); the ASUS vendor id 0x0b05 is not listed because it also covers keyboards and
    // mainboards. The Kinect v1 exposes motor, audio and camera devices; only the camera counts.
    static const std::vector<KnownDepthCamera> kCameras = {
        {0x1d27, std::nullopt, "PrimeSense / ASUS Xtion", "openni2"},
        {0x045e, 0x02ae, "Microsoft Kinect v1 (Xbox 360) camera", "freenect"},
        {0x045e, 0x02bf, "Microsoft Kinect for Windows camera", "freenect"},
        {0x2bc5, std::nullopt, "Orbbec", "openni2"},
    };
    return kCameras;
}

std::optional<KnownDepthCamera> FindDepthCamera(std::uint16_t vendor_id, std::uint16_t product_id) {
    for (const auto& known : KnownDepthCameras()) {
        if (known.vendor_id != vendor_id) continue;
        if (known.product_id && *known.product_id != product_id) continue;
        return known;
    }
    return std::nullopt;
}

std::string UsbIdString(std::uint16_t vendor_id, std::uint16_t product_id) {
    char text[16];
    std::snprintf(text, sizeof(text), "%04x:%04x", vendor_id, product_id);
    return text;
}

Result<std::vector<UsbDeviceInfo>> ListUsbDevices(bool all) {
    auto ctx = InitLibusb();
    if (!ctx) return ctx.error();
    DeviceList list(ctx->get());
    if (list.error() != 0) {
        return CameraError(std::string("libusb: cannot list devices: ") +
                           libusb_error_name(list.error()));
    }
    std::vector<UsbDeviceInfo> found;
    for (std::size_t i = 0; i < list.size(); ++i) {
        libusb_device_descriptor desc{};
        if (libusb_get_device_descriptor(list[i], &desc) != 0) continue;
        const auto known = FindDepthCamera(desc.idVendor, desc.idProduct);
        if (!known && !all) continue;
        UsbDeviceInfo info;
        info.vendor_id = desc.idVendor;
        info.product_id = desc.idProduct;
        if (known) {
            info.name = known->name;
            info.driver = known->driver;
            info.serial = SerialNumber(list[i], desc.iSerialNumber);
        }
        info.bus = libusb_get_bus_number(list[i]);
        info.address = libusb_get_device_address(list[i]);
        info.port_path = PortPath(list[i]);
        found.push_back(std::move(info));
    }
    return found;
}

std::optional<UsbAddress> UsbAddressFromOpenNiUri(const std::string& uri) {
    // PS1080 and Kinect URIs are "<vid>/<pid>@<bus>/<address>".
    static const std::regex kUri(R"(^[0-9a-fA-F]{4}/[0-9a-fA-F]{4}@(\d{1,3})/(\d{1,3})$)");
    std::smatch m;
    if (!std::regex_match(uri, m, kUri)) return std::nullopt;
    return UsbAddress{std::stoi(m[1].str()), std::stoi(m[2].str())};
}

Status ResetUsbDevice(const std::optional<UsbAddress>& address) {
    auto ctx = InitLibusb();
    if (!ctx) return ctx.error();
    DeviceList list(ctx->get());
    libusb_device* target = nullptr;
    for (std::size_t i = 0; i < list.size() && !target; ++i) {
        if (address) {
            if (libusb_get_bus_number(list[i]) == address->bus &&
                libusb_get_device_address(list[i]) == address->address) {
                target = list[i];
            }
            continue;
        }
        libusb_device_descriptor desc{};
        if (libusb_get_device_descriptor(list[i], &desc) == 0 &&
            FindDepthCamera(desc.idVendor, desc.idProduct)) {
            target = list[i];
        }
    }
    const std::string where =
        address ? "usb " + std::to_string(address->bus) + "/" + std::to_string(address->address)
                : "usb";
    if (!target) return CameraError(where + ": no such depth camera attached");
    libusb_device_handle* handle = nullptr;
    if (const int rc = libusb_open(target, &handle); rc != 0) {
        return CameraError(where + ": cannot open for reset: " + libusb_error_name(rc));
    }
    const int rc = libusb_reset_device(handle);
    libusb_close(handle);
    // NOT_FOUND after a reset means the device re-enumerated under a new address: that is the
    // expected outcome of a successful reset, not a failure.
    if (rc != 0 && rc != LIBUSB_ERROR_NOT_FOUND) {
        return CameraError(where + ": reset failed: " + libusb_error_name(rc));
    }
    return OkStatus();
}

Status ResetCameraOf(const std::string& driver, const std::string& serial, int index) {
    auto devices = ListUsbDevices();
    if (!devices) return devices.error();
    int seen = 0;
    for (const UsbDeviceInfo& d : *devices) {
        if (d.driver != driver) continue;
        if (serial.empty() ? seen++ == index : d.serial == serial) {
            return ResetUsbDevice(UsbAddress{d.bus, d.address});
        }
    }
    std::string which = serial;
    if (which.empty()) which.append("#").append(std::to_string(index));
    return CameraError("usb: no " + driver + " camera " + which + " attached");
}

}  // namespace boxd
