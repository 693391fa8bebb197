// libusb-1.0 implementation of UsbTransport.
#include <array>
#include <filesystem>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <libusb.h>

#include <hal/spectrometer/libusb_transport.h>
#include <hal/sysfs_file.h>

namespace replica::hal::spectrometer {
namespace {

UsbStatus statusOf(int rc)
{
    switch (rc) {
    case LIBUSB_SUCCESS:
        return UsbStatus::Ok;
    case LIBUSB_ERROR_TIMEOUT:
        return UsbStatus::Timeout;
    case LIBUSB_ERROR_NO_DEVICE:
        return UsbStatus::Gone;
    case LIBUSB_ERROR_PIPE:
        return UsbStatus::Stall;
    case LIBUSB_ERROR_OVERFLOW:
        return UsbStatus::Overflow;
    default:
        return UsbStatus::Io;
    }
}

struct ContextDeleter {
    void operator()(libusb_context* c) const { libusb_exit(c); }
};
using ContextPtr = std::unique_ptr<libusb_context, ContextDeleter>;

Expected<ContextPtr> makeContext()
{
    libusb_context* ctx = nullptr;
    if (const int rc = libusb_init(&ctx); rc != LIBUSB_SUCCESS) {
        return makeError(ErrorCode::Io, fmt::format("libusb could not start: {}; is /dev/bus/usb "
                                                    "available (in a container, pass it through)?",
                                                    libusb_strerror(rc)));
    }
    return ContextPtr(ctx);
}

class LibusbTransport final : public UsbTransport
{
public:
    LibusbTransport(ContextPtr ctx, libusb_device_handle* handle, UsbDeviceId id)
        : ctx_(std::move(ctx)), handle_(handle), id_(id)
    {}
    ~LibusbTransport() override
    {
        libusb_release_interface(handle_, 0);
        libusb_close(handle_);
    }
    LibusbTransport(const LibusbTransport&) = delete;
    LibusbTransport& operator=(const LibusbTransport&) = delete;

    UsbResult
    bulkWrite(std::uint8_t endpoint, std::span<const std::uint8_t> data, int timeoutMs) override
    {
        int done = 0;
        // libusb takes a non-const buffer for both directions; it does not write to an OUT one.
        const int rc = libusb_bulk_transfer(
                handle_, endpoint, const_cast<unsigned char*>(data.data()),
                static_cast<int>(data.size()), &done, static_cast<unsigned>(timeoutMs));
        return {statusOf(rc), static_cast<std::size_t>(done)};
    }

    UsbResult
    bulkRead(std::uint8_t endpoint, std::span<std::uint8_t> buffer, int timeoutMs) override
    {
        int done = 0;
        const int len = static_cast<int>(
                std::min<std::size_t>(buffer.size(), std::numeric_limits<int>::max()));
        const int rc = libusb_bulk_transfer(handle_, endpoint, buffer.data(), len, &done,
                                            static_cast<unsigned>(timeoutMs));
        return {statusOf(rc), static_cast<std::size_t>(done)};
    }

    UsbStatus clearHalt(std::uint8_t endpoint) override
    {
        return statusOf(libusb_clear_halt(handle_, endpoint));
    }

    std::string describe() const override
    {
        return fmt::format("USB bus {} address {} ({:04x}:{:04x})", id_.bus, id_.address,
                           id_.vendor, id_.product);
    }

private:
    ContextPtr ctx_;
    libusb_device_handle* handle_;
    UsbDeviceId id_;
};

// The first line of a sysfs attribute, without trailing white space ("" if unreadable, or not an
// attribute that answers at once: a FIFO or a device in its place is never waited for).
std::string sysfsLine(const std::filesystem::path& file)
{
    // A USB string descriptor is at most 126 UTF-16 units: a few hundred bytes of UTF-8.
    std::string line = readSysfsFile(file, 4096, SysfsRead::FirstLine).value_or(std::string());
    while (!line.empty() && (line.back() == '\n' || line.back() == ' ' || line.back() == '\r')) {
        line.pop_back();
    }
    return line;
}

int sysfsInt(const std::filesystem::path& file)
{
    const std::string text = sysfsLine(file);
    int v = 0;
    for (const char c : text) {
        if (c < '0' || c > '9' || v > 100000) {
            break;
        }
        v = v * 10 + (c - '0');
    }
    return text.empty() ? -1 : v;
}

// The serial number string read from the device itself (its string descriptor iSerialNumber);
// "" when it has none or cannot be opened.
std::string usbSerialFromDevice(libusb_device* dev)
{
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(dev, &d) != LIBUSB_SUCCESS || d.iSerialNumber == 0) {
        return {};
    }
    libusb_device_handle* h = nullptr;
    if (libusb_open(dev, &h) != LIBUSB_SUCCESS) {
        return {};
    }
    std::array<unsigned char, 128> text{};
    const int n = libusb_get_string_descriptor_ascii(h, d.iSerialNumber, text.data(),
                                                     static_cast<int>(text.size()));
    libusb_close(h);
    return n > 0 ? std::string(reinterpret_cast<const char*>(text.data()),
                               static_cast<std::size_t>(n))
                 : std::string();
}

std::string serialOf(libusb_device* dev, int bus, int address)
{
    std::string s = usbSerialFromSysfs(bus, address);
    return s.empty() ? usbSerialFromDevice(dev) : s;
}

} // namespace

std::string usbSerialFromSysfs(int bus, int address)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    for (fs::directory_iterator it("/sys/bus/usb/devices", ec), end; !ec && it != end;
         it.increment(ec)) {
        const fs::path dir = it->path();
        if (sysfsInt(dir / "busnum") == bus && sysfsInt(dir / "devnum") == address) {
            return sysfsLine(dir / "serial");
        }
    }
    return {};
}

Expected<std::vector<UsbDeviceId>> listUsbDevices(std::uint16_t vendor, std::uint16_t product)
{
    auto ctx = makeContext();
    if (!ctx) {
        return tl::unexpected(ctx.error());
    }
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(ctx->get(), &list);
    if (n < 0) {
        return makeError(ErrorCode::Io, fmt::format("libusb could not list devices: {}",
                                                    libusb_strerror(static_cast<int>(n))));
    }
    std::vector<UsbDeviceId> found;
    for (ssize_t i = 0; i < n; ++i) {
        libusb_device_descriptor d{};
        if (libusb_get_device_descriptor(list[i], &d) == LIBUSB_SUCCESS && d.idVendor == vendor &&
            d.idProduct == product) {
            const int b = libusb_get_bus_number(list[i]);
            const int a = libusb_get_device_address(list[i]);
            found.push_back({vendor, product, b, a, serialOf(list[i], b, a)});
        }
    }
    libusb_free_device_list(list, 1);
    return found;
}

namespace {

// Interface 0 of an opened device claimed, configuration 1 selected; closes the handle where that
// fails.
Expected<void>
claimInterface(libusb_device_handle* handle, std::uint16_t vendor, std::uint16_t product)
{
    int rc = LIBUSB_SUCCESS;
    // Detach a kernel driver only if one is bound (the USB2000+ normally has none). Not libusb's
    // auto-detach: that claims with USBDEVFS_DISCONNECT_CLAIM, which umockdev (the emulated device
    // of tests/umockdev) does not implement, where a plain claim works on both.
    if (libusb_kernel_driver_active(handle, 0) == 1) {
        libusb_detach_kernel_driver(handle, 0);
    }
    // Select configuration 1 only when it is not already active: setting the active configuration
    // again is a lightweight device reset (libusb's documentation), and the kernel has usually
    // chosen configuration 1 at enumeration.
    int active = 0;
    if (libusb_get_configuration(handle, &active) == LIBUSB_SUCCESS && active == 1) {
        rc = LIBUSB_SUCCESS;
    } else {
        rc = libusb_set_configuration(handle, 1);
    }
    if (rc != LIBUSB_SUCCESS && rc != LIBUSB_ERROR_BUSY) {
        libusb_close(handle);
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB device {:04x}:{:04x}: cannot select configuration 1: {}",
                                     vendor, product, libusb_strerror(rc)));
    }
    if (rc = libusb_claim_interface(handle, 0); rc != LIBUSB_SUCCESS) {
        libusb_close(handle);
        return makeError(ErrorCode::Io,
                         fmt::format("USB device {:04x}:{:04x}: cannot claim interface 0 ({}); "
                                     "is another program (OceanView, seabreeze) using it?",
                                     vendor, product, libusb_strerror(rc)));
    }
    return {};
}

} // namespace

Expected<std::unique_ptr<UsbTransport>> openLibusbTransport(std::uint16_t vendor,
                                                            std::uint16_t product,
                                                            int bus,
                                                            int address,
                                                            const std::string& serial)
{
    auto ctx = makeContext();
    if (!ctx) {
        return tl::unexpected(ctx.error());
    }
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(ctx->get(), &list);
    if (n < 0) {
        return makeError(ErrorCode::Io, fmt::format("libusb could not list devices: {}",
                                                    libusb_strerror(static_cast<int>(n))));
    }
    libusb_device* chosen = nullptr;
    UsbDeviceId id{vendor, product, 0, 0, {}};
    std::vector<std::string> others; // with a serial: the devices that have another one
    for (ssize_t i = 0; i < n && chosen == nullptr; ++i) {
        libusb_device_descriptor d{};
        if (libusb_get_device_descriptor(list[i], &d) != LIBUSB_SUCCESS || d.idVendor != vendor ||
            d.idProduct != product) {
            continue;
        }
        const int b = libusb_get_bus_number(list[i]);
        const int a = libusb_get_device_address(list[i]);
        if ((bus != 0 && bus != b) || (address != 0 && address != a)) {
            continue;
        }
        if (!serial.empty()) {
            const std::string found = serialOf(list[i], b, a);
            if (found != serial) {
                others.push_back(fmt::format("'{}' at bus {} address {}", found, b, a));
                continue;
            }
        }
        chosen = list[i];
        id.bus = b;
        id.address = a;
        id.serial = serial;
    }
    libusb_device_handle* handle = nullptr;
    int rc = chosen != nullptr ? libusb_open(chosen, &handle) : LIBUSB_ERROR_NOT_FOUND;
    libusb_free_device_list(list, 1);
    if (rc == LIBUSB_ERROR_NOT_FOUND && !serial.empty()) {
        std::string seen;
        for (const auto& o : others) {
            seen += (seen.empty() ? "" : ", ") + o;
        }
        return makeError(
                ErrorCode::NotFound,
                fmt::format("no USB device {:04x}:{:04x} with serial '{}' "
                            "(devices.spectrometer_serial): {}",
                            vendor, product, serial,
                            others.empty()
                                    ? "none of that kind is attached; check the "
                                      "cable and `lsusb`"
                                    : "attached: " + seen + "; set the serial of the one to use"));
    }
    if (rc == LIBUSB_ERROR_NOT_FOUND) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("no USB device {:04x}:{:04x} found: check the cable and "
                                     "`lsusb`",
                                     vendor, product));
    }
    if (rc == LIBUSB_ERROR_ACCESS) {
        return makeError(ErrorCode::Io,
                         fmt::format("USB device {:04x}:{:04x} at bus {} address {} is not "
                                     "accessible to this user: install deploy/udev/"
                                     "60-replica.rules and replug it",
                                     vendor, product, id.bus, id.address));
    }
    if (rc != LIBUSB_SUCCESS) {
        return makeError(ErrorCode::Io, fmt::format("could not open USB device {:04x}:{:04x}: {}",
                                                    vendor, product, libusb_strerror(rc)));
    }
    if (auto ok = claimInterface(handle, vendor, product); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::unique_ptr<UsbTransport>(
            std::make_unique<LibusbTransport>(std::move(*ctx), handle, id));
}

} // namespace replica::hal::spectrometer
