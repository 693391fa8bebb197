// USB2000+ device session over a UsbTransport.
#include <algorithm>
#include <chrono>
#include <span>
#include <thread>

#include <fmt/format.h>

#include <hal/spectrometer/usb2000_device.h>
#include <hal/spectrometer/usb2000_protocol.h>

namespace replica::hal::spectrometer {
namespace {

constexpr int kCommandTimeoutMs = 1'000;
// A spectrum arrives one integration time after the request at the latest; the margin covers USB
// scheduling and the readout itself (SeaBreeze uses a similar allowance).
constexpr int kSpectrumMarginMs = 500;

} // namespace

const char* toString(UsbStatus s)
{
    switch (s) {
    case UsbStatus::Ok:
        return "ok";
    case UsbStatus::Timeout:
        return "timed out";
    case UsbStatus::Gone:
        return "device unplugged";
    case UsbStatus::Stall:
        return "endpoint stalled";
    case UsbStatus::Overflow:
        return "overflow";
    case UsbStatus::Io:
        return "I/O error";
    }
    return "unknown";
}

Error Usb2000Device::transferError(UsbStatus s, const char* what) const
{
    const ErrorCode code = s == UsbStatus::Gone ? ErrorCode::NotFound : ErrorCode::DeviceFailure;
    return Error{code, fmt::format("USB2000+ at {}: {} failed: {}", transport_->describe(), what,
                                   toString(s))};
}

Expected<std::unique_ptr<Usb2000Device>>
Usb2000Device::open(std::unique_ptr<UsbTransport> transport)
{
    std::unique_ptr<Usb2000Device> dev(new Usb2000Device(std::move(transport)));
    for (const std::uint8_t ep :
         {usb2000::kEpCommandOut, usb2000::kEpReplyIn, usb2000::kEpSpectrumIn}) {
        if (const UsbStatus s = dev->transport_->clearHalt(ep); s == UsbStatus::Gone) {
            return tl::unexpected(dev->transferError(s, "clearing an endpoint halt"));
        }
    }
    if (auto ok = dev->send(usb2000::initialise()); !ok) {
        return tl::unexpected(ok.error());
    }
    // The device needs about 100 ms after initialisation before it answers reliably.
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (auto ok = dev->readCalibration(); !ok) {
        return tl::unexpected(ok.error());
    }
    if (auto ok = dev->send(usb2000::setTriggerMode(0)); !ok) { // free running
        return tl::unexpected(ok.error());
    }
    if (auto ok = dev->setIntegrationTime(dev->integrationUs_); !ok) {
        return tl::unexpected(ok.error());
    }
    return dev;
}

Expected<void> Usb2000Device::send(const std::vector<std::uint8_t>& bytes)
{
    const UsbResult r = transport_->bulkWrite(usb2000::kEpCommandOut, bytes, kCommandTimeoutMs);
    if (r.status != UsbStatus::Ok) {
        return tl::unexpected(
                transferError(r.status, fmt::format("command 0x{:02x}", bytes.front()).c_str()));
    }
    if (r.transferred != bytes.size()) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB2000+ at {}: command 0x{:02x} sent {} of {} bytes",
                                     transport_->describe(), bytes.front(), r.transferred,
                                     bytes.size()));
    }
    return {};
}

Expected<std::vector<std::uint8_t>> Usb2000Device::querySlot(std::uint8_t slot)
{
    if (auto ok = send(usb2000::querySlot(slot)); !ok) {
        return tl::unexpected(ok.error());
    }
    // Read more than a reply's size so that a device that says too much is noticed.
    std::vector<std::uint8_t> reply(64);
    const UsbResult r = transport_->bulkRead(usb2000::kEpReplyIn, reply, kCommandTimeoutMs);
    if (r.status != UsbStatus::Ok) {
        return tl::unexpected(
                transferError(r.status, fmt::format("reading EEPROM slot {}", slot).c_str()));
    }
    reply.resize(r.transferred);
    auto data = usb2000::slotData(reply, slot);
    if (!data) {
        return tl::unexpected(data.error());
    }
    return std::vector<std::uint8_t>(data->begin(), data->end());
}

Expected<void> Usb2000Device::readCalibration()
{
    auto serial = querySlot(usb2000::kSlotSerial);
    if (!serial) {
        return tl::unexpected(serial.error());
    }
    calibration_.serial = usb2000::slotText(*serial);
    // Slots first, first + 1, ... as numbers into out[0], out[1], ...
    const auto numbers = [this](int first, std::span<double> out) -> Expected<void> {
        for (std::size_t i = 0; i < out.size(); ++i) {
            const auto slot = static_cast<std::uint8_t>(first + static_cast<int>(i));
            auto data = querySlot(slot);
            if (!data) {
                return tl::unexpected(data.error());
            }
            auto value = usb2000::slotNumber(*data, slot);
            if (!value) {
                return tl::unexpected(value.error());
            }
            out[i] = *value;
        }
        return {};
    };
    if (auto ok = numbers(usb2000::kSlotWavelength0, calibration_.wavelengthCoeffs); !ok) {
        return ok;
    }
    auto orderData = querySlot(usb2000::kSlotNonlinearityOrder);
    if (!orderData) {
        return tl::unexpected(orderData.error());
    }
    auto order = usb2000::slotNumber(*orderData, usb2000::kSlotNonlinearityOrder);
    if (!order || *order < 0.0 || *order > 7.0) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB2000+ at {}: EEPROM slot 14 (non-linearity order) holds "
                                     "'{}', not 0..7; re-flash the calibration",
                                     transport_->describe(), usb2000::slotText(*orderData)));
    }
    calibration_.nonlinearityOrder = static_cast<int>(*order);
    calibration_.nonlinearityCoeffs.fill(0.0);
    if (auto ok = numbers(
                usb2000::kSlotNonlinearity0,
                std::span(calibration_.nonlinearityCoeffs)
                        .first(static_cast<std::size_t>(calibration_.nonlinearityOrder) + 1));
        !ok) {
        return ok;
    }
    auto sat = querySlot(usb2000::kSlotSaturation);
    if (!sat) {
        return tl::unexpected(sat.error());
    }
    calibration_.saturationCounts = usb2000::slotSaturation(*sat);
    return {};
}

Expected<void> Usb2000Device::setIntegrationTime(std::uint32_t us)
{
    const std::uint32_t clamped = usb2000::clampIntegrationUs(us);
    if (auto ok = send(usb2000::setIntegrationTime(clamped)); !ok) {
        return ok;
    }
    integrationUs_ = clamped;
    discardNext_ = true; // free-running: the next spectrum may carry the old exposure
    return {};
}

Expected<RawSpectrum> Usb2000Device::readOne()
{
    if (auto ok = send(usb2000::requestSpectrum()); !ok) {
        return tl::unexpected(ok.error());
    }
    std::vector<std::uint8_t> bytes(usb2000::kSpectrumBytes + 512);
    const int timeoutMs = static_cast<int>(integrationUs_ / 1000) + kSpectrumMarginMs;
    const UsbResult r = transport_->bulkRead(usb2000::kEpSpectrumIn, bytes, timeoutMs);
    if (r.status != UsbStatus::Ok) {
        return tl::unexpected(transferError(r.status, "reading a spectrum"));
    }
    bytes.resize(r.transferred);
    auto counts = usb2000::parseSpectrum(bytes);
    if (!counts) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("{} (at {})", counts.error().message, transport_->describe()));
    }
    RawSpectrum s;
    s.integrationTimeUs = integrationUs_;
    s.saturated = std::any_of(counts->begin(), counts->end(),
                              [&](std::uint16_t c) { return c >= calibration_.saturationCounts; });
    s.counts = std::move(*counts);
    return s;
}

Expected<RawSpectrum> Usb2000Device::readSpectrum()
{
    if (discardNext_) {
        discardNext_ = false;
        auto stale = readOne();
        if (!stale) {
            if (stale.error().code != ErrorCode::NotFound) {
                (void)resynchronise();
            }
            return stale;
        }
        ++discarded_;
    }
    auto s = readOne();
    if (!s && s.error().code != ErrorCode::NotFound) {
        if (auto again = resynchronise(); !again) {
            return tl::unexpected(again.error());
        }
    }
    return s;
}

Expected<void> Usb2000Device::resynchronise()
{
    ++resyncs_;
    // Drain whatever is left of a partial spectrum, then start again from a clean state.
    std::vector<std::uint8_t> sink(usb2000::kSpectrumBytes + 512);
    for (int i = 0; i < 4; ++i) {
        const UsbResult r = transport_->bulkRead(usb2000::kEpSpectrumIn, sink, 20);
        if (r.status == UsbStatus::Gone) {
            return tl::unexpected(transferError(r.status, "draining the spectrum endpoint"));
        }
        if (r.status != UsbStatus::Ok || r.transferred == 0) {
            break;
        }
    }
    for (const std::uint8_t ep : {usb2000::kEpSpectrumIn, usb2000::kEpReplyIn}) {
        if (const UsbStatus st = transport_->clearHalt(ep); st == UsbStatus::Gone) {
            return tl::unexpected(transferError(st, "clearing an endpoint halt"));
        }
    }
    if (auto ok = send(usb2000::initialise()); !ok) {
        return ok;
    }
    return setIntegrationTime(integrationUs_);
}

} // namespace replica::hal::spectrometer
