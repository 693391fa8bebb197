// The live HidDevice: hidapi's hidraw backend on a /dev/hidrawN node, with the report descriptor
// read from sysfs (hidapi 0.13, Debian 12's, has no hid_get_report_descriptor). Also the list of
// HID eye/head trackers a machine has, found by parsing each hidraw node's report descriptor.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <hal/tracker/hid_device.h>

namespace replica::hal::hid {

struct HidrawNode {
    std::string devNode;            // /dev/hidrawN
    std::filesystem::path sysfsDir; // /sys/class/hidraw/hidrawN
    std::string name;               // HID_NAME from the uevent
    std::uint16_t vendor = 0;
    std::uint16_t product = 0;
    std::string layout; // Layout::summary() for a tracker
    std::string error;  // why it is not usable as a tracker (empty: it is one)
};

// Every hidraw node under sysfsRoot (default /sys/class/hidraw) whose report descriptor has an
// application collection of the Eye and Head Trackers page, recognised or not (error says why
// one cannot be used).
std::vector<HidrawNode>
listHidTrackers(const std::filesystem::path& sysfsRoot = "/sys/class/hidraw",
                const std::filesystem::path& devRoot = "/dev");

// Reads /sys/class/hidraw/hidrawN/device/report_descriptor.
Expected<std::vector<std::uint8_t>>
readSysfsReportDescriptor(const std::filesystem::path& sysfsDir);

// Opens 'devNode' (empty: the first tracker listHidTrackers finds) with hidapi. Errors name the
// node and the fix (permissions: deploy/udev/60-replica.rules).
HidOpener hidapiOpener(std::string devNode,
                       std::filesystem::path sysfsRoot = "/sys/class/hidraw",
                       std::filesystem::path devRoot = "/dev");

} // namespace replica::hal::hid
