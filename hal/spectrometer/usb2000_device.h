// One opened USB2000+: reads its EEPROM calibration, sets the integration time and reads raw
// spectra, recovering from lost synchronisation the way SeaBreeze does (drain, clear halt,
// re-initialise). Speaks only through a UsbTransport, so tests drive it with a byte-level fake.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <hal/spectrometer/usb_transport.h>
#include <pipeline/base/expected.h>

namespace replica::hal::spectrometer {

struct Usb2000Calibration {
    std::string serial;
    std::array<double, 4> wavelengthCoeffs{};   // nm at pixel p = c0 + c1 p + c2 p^2 + c3 p^3
    std::array<double, 8> nonlinearityCoeffs{}; // k0..k7, zero above the programmed order
    int nonlinearityOrder = 0;
    std::uint16_t saturationCounts = 65535; // raw counts at which the detector saturates
};

struct RawSpectrum {
    std::vector<std::uint16_t> counts;
    std::uint32_t integrationTimeUs = 0;
    bool saturated = false; // some pixel reached the saturation level
};

class Usb2000Device
{
public:
    // Takes the transport of an opened, claimed device; initialises it and reads its calibration.
    // Error code NotFound when the device went away, DeviceFailure when it misbehaved.
    static Expected<std::unique_ptr<Usb2000Device>> open(std::unique_ptr<UsbTransport> transport);

    const Usb2000Calibration& calibration() const { return calibration_; }
    std::uint32_t integrationTimeUs() const { return integrationUs_; }
    std::string describe() const { return transport_->describe(); }

    // Clamps to the device's range and 1 ms steps; the next spectrum, which may still carry the
    // old exposure, is read and thrown away.
    Expected<void> setIntegrationTime(std::uint32_t us);

    // Requests one spectrum and waits for it (integration time + margin). On a sync error it
    // resynchronises once and reports the failure; the caller simply asks again.
    Expected<RawSpectrum> readSpectrum();

    // Counters for the log and for tests.
    int resyncCount() const { return resyncs_; }
    int discardedCount() const { return discarded_; }

private:
    explicit Usb2000Device(std::unique_ptr<UsbTransport> t) : transport_(std::move(t)) {}

    Expected<void> send(const std::vector<std::uint8_t>& bytes);
    Expected<std::vector<std::uint8_t>> querySlot(std::uint8_t slot);
    Expected<void> readCalibration();
    Expected<RawSpectrum> readOne();
    Expected<void> resynchronise();
    Error transferError(UsbStatus s, const char* what) const;

    std::unique_ptr<UsbTransport> transport_;
    Usb2000Calibration calibration_;
    std::uint32_t integrationUs_ = 100'000;
    bool discardNext_ = false;
    int resyncs_ = 0;
    int discarded_ = 0;
};

} // namespace replica::hal::spectrometer
