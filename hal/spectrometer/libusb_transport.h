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
};

// Every attached device with this vendor and product id.
Expected<std::vector<UsbDeviceId>> listUsbDevices(std::uint16_t vendor, std::uint16_t product);

// Opens the first matching device (or the one at bus/address when given), detaches a kernel
// driver if one is bound and claims interface 0. Errors say what to check: cable, udev rule
// (deploy/udev/60-replica.rules), another program holding the device.
Expected<std::unique_ptr<UsbTransport>>
openLibusbTransport(std::uint16_t vendor, std::uint16_t product, int bus = 0, int address = 0);

} // namespace replica::hal::spectrometer
