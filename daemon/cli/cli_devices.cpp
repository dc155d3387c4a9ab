// `boxd devices`: lists the depth cameras attached over USB (libusb) with the camera.driver for
// each and its serial number, as a table or JSON lines.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "daemon/cli/cli.h"
#include "drivers/usb_devices.h"
#include "pipeline/core/json_text.h"

namespace boxd::cli {

namespace {

struct DevicesOptions {
    bool json = false;
    bool all = false;
};

int RunDevices(const DevicesOptions& options) {
    auto devices = ListUsbDevices(options.all);
    if (!devices) return Fail(devices.error());
    if (options.json) {
        for (const UsbDeviceInfo& d : *devices) {
            const nlohmann::json line = {{"vendor_id", UsbIdString(d.vendor_id, 0).substr(0, 4)},
                                         {"product_id", UsbIdString(d.product_id, 0).substr(0, 4)},
                                         {"name", d.name},
                                         {"driver", d.driver},
                                         {"serial", d.serial},
                                         {"bus", d.bus},
                                         {"address", d.address},
                                         {"port_path", d.port_path}};
            std::printf("%s\n", JsonText(line).c_str());
        }
        if (devices->empty()) {
            std::fprintf(stderr, "boxd: %s\n",
                         options.all ? "no USB devices found" : "no depth cameras found");
        }
        return kExitOk;
    }
    if (devices->empty()) {
        std::printf("%s\n", options.all ? "no USB devices found" : "no depth cameras found");
        return kExitOk;
    }
    std::printf("%-9s  %-3s  %-4s  %-12s  %-8s  %-18s  %s\n", "ID", "BUS", "ADDR", "PORT", "DRIVER",
                "SERIAL", "NAME");
    const auto or_dash = [](const std::string& s) { return s.empty() ? "-" : s.c_str(); };
    for (const UsbDeviceInfo& d : *devices) {
        std::printf("%-9s  %03d  %04d  %-12s  %-8s  %-18s  %s\n",
                    UsbIdString(d.vendor_id, d.product_id).c_str(), d.bus, d.address,
                    d.port_path.c_str(), or_dash(d.driver), or_dash(d.serial), or_dash(d.name));
    }
    return kExitOk;
}

}  // namespace

void AddDevices(CLI::App& app, Runner& run) {
    auto options = std::make_shared<DevicesOptions>();
    CLI::App* sub = app.add_subcommand("devices", "List the attached depth cameras (USB)");
    sub->add_flag("--json", options->json, "One JSON object per line instead of a table");
    sub->add_flag("--all", options->all, "List every USB device, not only depth cameras");
    sub->callback([&run, options] { run = [options] { return RunDevices(*options); }; });
}

}  // namespace boxd::cli
