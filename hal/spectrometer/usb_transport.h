// The USB seam under the spectrometer driver: bulk transfers on numbered endpoints. The live
// implementation is libusb (libusb_transport.h); tests put a byte-level fake of the device behind
// it, so everything above this line is exercised without hardware.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include <pipeline/base/expected.h>

namespace replica::hal::spectrometer {

// Why a transfer failed, in the terms the driver acts on.
enum class UsbStatus {
    Ok,
    Timeout,  // nothing arrived in time: the device may still be integrating
    Gone,     // unplugged (LIBUSB_ERROR_NO_DEVICE): reopen later
    Stall,    // endpoint halted: clear the halt and resynchronise
    Overflow, // the device sent more than asked for: lost synchronisation
    Io,       // anything else
};

const char* toString(UsbStatus s);

struct UsbResult {
    UsbStatus status = UsbStatus::Ok;
    std::size_t transferred = 0;
};

class UsbTransport
{
public:
    virtual ~UsbTransport() = default;
    virtual UsbResult
    bulkWrite(std::uint8_t endpoint, std::span<const std::uint8_t> data, int timeoutMs) = 0;
    virtual UsbResult
    bulkRead(std::uint8_t endpoint, std::span<std::uint8_t> buffer, int timeoutMs) = 0;
    virtual UsbStatus clearHalt(std::uint8_t endpoint) = 0;
    // Where the device is, for messages: "USB bus 1 address 5 (2457:101e)".
    virtual std::string describe() const = 0;
};

} // namespace replica::hal::spectrometer
