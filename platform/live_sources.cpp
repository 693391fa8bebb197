// Live sources for 'replica run --hal live'.
#include <algorithm>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include <hal/accel/iio_accel.h>
#include <hal/lamp/gpio_lamp_source.h>
#include <hal/lamp/libgpiod_lines.h>
#include <hal/spectrometer/usb2000_protocol.h>
#include <hal/spectrometer/usb2000_source.h>
#include <hal/tracker/hid_tracker_source.h>
#include <hal/tracker/hidapi_device.h>
#include <hal/tracker/opentrack_source.h>
#include <pipeline/spectral/spectrometer_chain.h>
#include <platform/live_sources.h>

namespace replica::platform {

namespace {

// The pipeline's auto-integration controller, seen from the driver thread.
std::uint32_t autoIntegration(const hal::SpectrumSample& s)
{
    namespace usb2000 = hal::spectrometer::usb2000;
    if (s.counts.size() <= static_cast<std::size_t>(usb2000::kDarkPixelLast)) {
        return 0;
    }
    const auto first = s.counts.begin() + usb2000::kDarkPixelFirst;
    const auto last = s.counts.begin() + usb2000::kDarkPixelLast + 1;
    const double dark = std::accumulate(first, last, 0.0) / static_cast<double>(last - first);
    pipeline::spectral::AutoIntegrationParams params;
    if (s.saturated) {
        // The driver judged saturation against the EEPROM level, which may sit below 65535: make
        // the controller see it too.
        params.saturationCounts = *std::max_element(s.counts.begin(), s.counts.end());
    }
    const auto d =
            pipeline::spectral::nextIntegrationTime(s.counts, dark, s.integrationTimeUs, params);
    return d.changed ? d.integrationTimeUs : 0;
}

} // namespace

Expected<Sources>
makeLiveSources(const hal::Clock& clock, const LiveOptions& options, std::size_t lampCount)
{
    const auto live = [&options](const recordings::DeviceKindBase& kind) {
        const auto it = options.devices.find(kind.name());
        return it != options.devices.end() ? it->second : std::string();
    };
    const std::string trackerFrom = live(recordings::trackerKind());
    std::optional<hal::lamp::GpioLineSpec> lampLines;
    if (live(recordings::lampSelectorKind()) == "gpio" && !options.lampGpio.empty()) {
        auto spec = hal::lamp::parseGpioLineSpec(options.lampGpio);
        if (!spec) {
            return tl::unexpected(spec.error());
        }
        if (spec->offsets.size() != lampCount) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("--lamp-gpio {}: {} lines for a booth with {} lamps; give "
                                         "one line per lamp, in the booth's lamp order",
                                         options.lampGpio, spec->offsets.size(), lampCount));
        }
        lampLines = std::move(*spec);
    }
    Sources s;
    if (trackerFrom == "opentrack") {
        hal::tracker::OpentrackSourceOptions trackerOptions;
        trackerOptions.port = options.trackerPort;
        trackerOptions.bindAddress = options.trackerBind;
        auto tracker = hal::tracker::makeOpentrackSource(clock, trackerOptions);
        if (!tracker) {
            return tl::unexpected(tracker.error());
        }
        s.set(recordings::trackerKind(), std::move(*tracker));
    } else if (trackerFrom == "hid") {
        hal::tracker::HidTrackerOptions hidOptions;
        auto axes = hal::accel::parseAxisMapping(options.trackerAxes);
        if (!axes) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("--tracker-axes {}: {}", options.trackerAxes,
                                         axes.error().message));
        }
        hidOptions.axes = *axes;
        hidOptions.label = options.hidTracker.empty() ? "auto" : options.hidTracker;
        // Absent at start is not fatal: Lost, one error line, retry every second.
        s.set(recordings::trackerKind(),
              hal::tracker::makeHidTrackerSource(hal::hid::hidapiOpener(options.hidTracker), clock,
                                                 std::move(hidOptions)));
    } else if (!trackerFrom.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("live tracker '{}': expected opentrack or hid", trackerFrom));
    }
    if (live(recordings::spectrometerKind()) == "live") {
        hal::spectrometer::Usb2000SourceOptions specOptions;
        specOptions.nextIntegrationUs = autoIntegration;
        s.set(recordings::spectrometerKind(),
              hal::spectrometer::makeUsb2000Source(
                      hal::spectrometer::libusbUsb2000Opener(options.spectrometerSerial), clock,
                      std::move(specOptions)));
    }
    if (live(recordings::accelKind()) == "live") {
        hal::accel::IioAccelSourceOptions accelOptions;
        auto mounting = hal::accel::parseAxisMapping(options.accelAxes);
        if (!mounting) {
            return tl::unexpected(mounting.error());
        }
        accelOptions.mounting = *mounting;
        accelOptions.root = options.iioRoot;
        accelOptions.name = options.accelName;
        s.set(recordings::accelKind(),
              hal::accel::makeIioAccelSource(clock, std::move(accelOptions)));
    }
    if (lampLines) {
        // A chip that cannot be opened is not fatal: the source reports Lost and retries, and
        // the light comes from the spectrometer alone meanwhile.
        hal::lamp::GpioLampSourceOptions lampOptions;
        lampOptions.lines = std::move(*lampLines);
        s.set(recordings::lampSelectorKind(),
              hal::lamp::makeGpioLampSource(hal::lamp::libgpiodOpener(), clock,
                                            std::move(lampOptions)));
    }
    return s;
}

} // namespace replica::platform
