// The USB2000+ driver on the real libusb path, against an emulated device: run under umockdev-run
// with usb2000.umockdev (the device's sysfs and USB descriptors) and the ioctl record that
// make_usb2000_ioctl.py writes. Unmodified libusb enumerates 2457:101e, claims it and does real
// bulk transfers that umockdev answers from the record; a device is chosen by its USB serial
// (devices.spectrometer_serial). Exit 0 on success, 1 with a reason.
#include <cstdio>
#include <string>

#include <hal/spectrometer/libusb_transport.h>
#include <hal/spectrometer/usb2000_device.h>
#include <hal/spectrometer/usb2000_protocol.h>

namespace {

int fail(const std::string& why)
{
    std::fprintf(stderr, "FAIL: %s\n", why.c_str());
    return 1;
}

} // namespace

int main()
{
    namespace spec = replica::hal::spectrometer;
    auto devices = spec::listUsbDevices(spec::usb2000::kVendorId, spec::usb2000::kProductId);
    if (!devices || devices->size() != 1) {
        return fail(devices ? "expected one emulated USB2000+, found " +
                                      std::to_string(devices->size())
                            : devices.error().message);
    }
    // The serial number string comes from the device record's sysfs 'serial' (the kernel's copy
    // of the string descriptor), not from the EEPROM record the driver reads later.
    if ((*devices)[0].serial != "USB2+F00001") {
        return fail("USB serial read back as '" + (*devices)[0].serial + "'");
    }
    // devices.spectrometer_serial naming another instrument: NotFound (the source stays Lost and
    // retries), and the message names the serial asked for and the one attached.
    auto other = spec::openLibusbTransport(spec::usb2000::kVendorId, spec::usb2000::kProductId, 0,
                                           0, "USB2+F09999");
    if (other || other.error().code != replica::ErrorCode::NotFound ||
        other.error().message.find("'USB2+F09999'") == std::string::npos ||
        other.error().message.find("'USB2+F00001' at bus 1 address 2") == std::string::npos) {
        return fail("a serial no device has must be NotFound naming both serials, got " +
                    (other ? std::string("an open device") : other.error().message));
    }
    const std::string noMatch = other.error().message;
    // The device whose serial it is: the rest of the session on it.
    auto transport = spec::openLibusbTransport(spec::usb2000::kVendorId, spec::usb2000::kProductId,
                                               0, 0, "USB2+F00001");
    if (!transport) {
        return fail("open: " + transport.error().message);
    }
    const std::string where = (*transport)->describe();
    auto dev = spec::Usb2000Device::open(std::move(*transport));
    if (!dev) {
        return fail("initialise and EEPROM read: " + dev.error().message);
    }
    const auto& cal = (*dev)->calibration();
    if (cal.serial != "USB2+F00001" || cal.wavelengthCoeffs[0] != 339.2 ||
        cal.wavelengthCoeffs[1] != 0.3797 || cal.wavelengthCoeffs[3] != -1.3e-10 ||
        cal.nonlinearityOrder != 1 || cal.nonlinearityCoeffs[1] != -2e-06 ||
        cal.saturationCounts != 60000) {
        return fail("calibration read back wrong: serial " + cal.serial);
    }
    auto s = (*dev)->readSpectrum(); // discards the first after the integration time was set
    if (!s) {
        return fail("spectrum: " + s.error().message);
    }
    // The second recorded spectrum: peak 30001 at pixel 1010, ramp 1000 + (i % 1024) / 8.
    if (s->counts.size() != 2048 || s->counts[1010] != 30001 || s->counts[7] != 1000 ||
        s->counts[2047] != 1000 + 1023 / 8 || s->integrationTimeUs != 100000 || s->saturated) {
        return fail("spectrum content wrong");
    }
    auto gone = (*dev)->readSpectrum();
    if (gone || gone.error().code != replica::ErrorCode::NotFound) {
        return fail("an unplugged device must read as NotFound (reopen later), got " +
                    (gone ? std::string("a spectrum") : gone.error().message));
    }
    std::printf("ok: another serial -> '%s'\n", noMatch.c_str());
    std::printf("ok: %s: EEPROM serial %s, c0 %.1f nm, saturation %u; spectrum peak %u at pixel "
                "1010; unplug -> '%s'\n",
                where.c_str(), cal.serial.c_str(), cal.wavelengthCoeffs[0],
                static_cast<unsigned>(cal.saturationCounts), s->counts[1010],
                gone.error().message.c_str());
    return 0;
}
