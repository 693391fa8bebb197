// The live spectrometer source: a USB2000+ read on its own thread about five times a second,
// samples stamped in session time and queued for the loop. Survives unplugging: it reports Lost,
// retries every second and resumes with the same calibration checks.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <hal/clock.h>
#include <hal/sources.h>
#include <hal/spectrometer/usb2000_device.h>

namespace replica::hal::spectrometer {

struct Usb2000SourceOptions {
    std::int64_t periodNs = 200'000'000; // one spectrum every 200 ms, as in the paper
    std::uint32_t initialIntegrationUs = 100'000;
    std::int64_t reconnectNs = 1'000'000'000;
    std::size_t queueCapacity = 64; // beyond this the oldest sample is dropped (and counted)
    // Called with every spectrum; returns the integration time for the next one (0 = keep).
    // The platform plugs the pipeline's auto-integration controller in here.
    std::function<std::uint32_t(const SpectrumSample&)> nextIntegrationUs;
};

// Opens a transport to the device, or says why not (NotFound while unplugged).
using TransportOpener = std::function<Expected<std::unique_ptr<UsbTransport>>()>;

// The opener for real hardware: the first USB2000+ on the bus, or with a serial the one whose USB
// serial number string is that (NotFound, naming the serials attached, while none is).
TransportOpener libusbUsb2000Opener(std::string serial = {});

// Starts the reader thread at once; the first open attempt happens on it, so construction never
// blocks on USB. state() is Lost until a device has been opened.
std::unique_ptr<SpectrometerSource>
makeUsb2000Source(TransportOpener opener, const Clock& clock, Usb2000SourceOptions options = {});

} // namespace replica::hal::spectrometer
