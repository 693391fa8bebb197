// The live UsbTransport: libusb-1.0 bulk transfers on an opened, claimed device.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <hal/spectrometer/usb_transport.h>
#include <pipeline/base/expected.h>

namespace replica::hal::spectrometer {

struct UsbDeviceId {
    std::uint16_t vendor = 0;
    std::uint16_t product = 0;
    int bus = 0;
    int address = 0;
    std::string serial; // the USB serial number string ("" when the device gives none)
};

// The USB serial number string of the device at bus/address: the kernel's copy of its string
// descriptor iSerialNumber (sysfs 'serial' under /sys/bus/usb/devices), "" when there is none.
std::string usbSerialFromSysfs(int bus, int address);

// Every attached device with this vendor and product id.
Expected<std::vector<UsbDeviceId>> listUsbDevices(std::uint16_t vendor, std::uint16_t product);

// Opens the first matching device (or the one at bus/address when given; with a serial, the one
// whose USB serial number string is exactly that: from sysfs, else read from the device's string
// descriptor), detaches a kernel driver if one is bound and claims interface 0. Errors say what to
// check: cable, udev rule (deploy/udev/60-replica.rules), another program holding the device;
// with a serial that no attached device has, NotFound naming the serials that are attached.
Expected<std::unique_ptr<UsbTransport>> openLibusbTransport(std::uint16_t vendor,
                                                            std::uint16_t product,
                                                            int bus = 0,
                                                            int address = 0,
                                                            const std::string& serial = {});

} // namespace replica::hal::spectrometer
