// Reader thread for the live USB2000+.
#include <algorithm>
#include <atomic>
#include <string>
#include <thread>

#include <spdlog/spdlog.h>

#include <hal/live_queue.h>
#include <hal/log.h>
#include <hal/spectrometer/libusb_transport.h>
#include <hal/spectrometer/usb2000_protocol.h>
#include <hal/spectrometer/usb2000_source.h>

namespace replica::hal::spectrometer {
namespace {

class Usb2000Source final : public SpectrometerSource
{
public:
    Usb2000Source(TransportOpener opener, const Clock& clock, Usb2000SourceOptions options)
        : opener_(std::move(opener)), clock_(clock), options_(std::move(options)),
          queue_(options_.queueCapacity)
    {
        info_.model = "USB2000+";
        info_.kind = SourceKind::Live;
        thread_ = std::thread([this] { run(); });
    }

    ~Usb2000Source() override
    {
        queue_.stop();
        thread_.join();
    }

    Usb2000Source(const Usb2000Source&) = delete;
    Usb2000Source& operator=(const Usb2000Source&) = delete;

    const DeviceInfo& info() const override { return info_; }

    LinkState state() const override { return state_.load(); }

    void poll(std::int64_t untilNs, std::vector<SpectrumSample>& out) override
    {
        queue_.drain(untilNs, out);
    }

private:
    // Sleeps until 'ns' of session time have passed or the source is stopped; false when stopped.
    bool waitFor(std::int64_t ns) { return queue_.waitFor(ns); }

    bool stopping() const { return queue_.stopping(); }

    void run()
    {
        std::string lastError;
        while (!stopping()) {
            if (!device_) {
                auto transport = opener_();
                auto dev = transport ? Usb2000Device::open(std::move(*transport))
                                     : Expected<std::unique_ptr<Usb2000Device>>(
                                               tl::unexpected(transport.error()));
                if (!dev) {
                    state_ = LinkState::Lost;
                    if (dev.error().message != lastError) {
                        deviceLog("hal.spectrometer")
                                ->error("{}; retrying every {} ms", dev.error().message,
                                        options_.reconnectNs / 1'000'000);
                        lastError = dev.error().message;
                    }
                    if (!waitFor(options_.reconnectNs)) {
                        return;
                    }
                    continue;
                }
                device_ = std::move(*dev);
                lastError.clear();
                if (auto ok = device_->setIntegrationTime(options_.initialIntegrationUs); !ok) {
                    dropDevice(ok.error());
                    continue;
                }
                deviceLog("hal.spectrometer")
                        ->info("USB2000+ serial {} at {}, saturation {} counts",
                               device_->calibration().serial, device_->describe(),
                               device_->calibration().saturationCounts);
                state_ = LinkState::Connected;
            }
            const std::int64_t started = clock_.nowNs();
            auto raw = device_->readSpectrum();
            if (!raw) {
                if (raw.error().code == ErrorCode::NotFound) {
                    dropDevice(raw.error());
                    continue;
                }
                // A read that fails fast (a timeout the device answers at once, garbage) must
                // not spin: one line per new error, and the next try after a period.
                state_ = LinkState::Stalled;
                if (raw.error().message != lastError) {
                    deviceLog("hal.spectrometer")->warn("{}", raw.error().message);
                    lastError = raw.error().message;
                }
                if (!waitFor(options_.periodNs > 0 ? options_.periodNs : 1'000'000)) {
                    return;
                }
                continue;
            }
            state_ = LinkState::Connected;
            lastError.clear();
            SpectrumSample s;
            s.timestampNs = clock_.nowNs();
            s.sequence = sequence_++;
            s.integrationTimeUs = raw->integrationTimeUs;
            s.counts = std::move(raw->counts);
            s.wavelengthCoeffs = device_->calibration().wavelengthCoeffs;
            s.nonlinearityCoeffs = device_->calibration().nonlinearityCoeffs;
            s.saturated = raw->saturated;
            if (options_.nextIntegrationUs) {
                const std::uint32_t next = options_.nextIntegrationUs(s);
                if (next != 0 &&
                    usb2000::clampIntegrationUs(next) != device_->integrationTimeUs()) {
                    if (auto ok = device_->setIntegrationTime(next); !ok) {
                        deviceLog("hal.spectrometer")->warn("{}", ok.error().message);
                    }
                }
            }
            push(std::move(s));
            if (!waitFor(options_.periodNs - (clock_.nowNs() - started))) {
                return;
            }
        }
    }

    void push(SpectrumSample s)
    {
        // Beyond the queue's capacity the oldest spectrum goes; say so now and then.
        const std::uint64_t dropped = queue_.push(std::move(s));
        if (dropped != dropped_) {
            dropped_ = dropped;
            if (dropped_ == 1 || dropped_ % 100 == 0) {
                deviceLog("hal.spectrometer")
                        ->warn("the loop is not consuming spectra; {} dropped", dropped_);
            }
        }
    }

    void dropDevice(const Error& e)
    {
        deviceLog("hal.spectrometer")
                ->error("{}; the display keeps the last known light", e.message);
        device_.reset();
        state_ = LinkState::Lost;
    }

    TransportOpener opener_;
    const Clock& clock_;
    Usb2000SourceOptions options_;
    DeviceInfo info_;
    std::atomic<LinkState> state_{LinkState::Lost};
    std::unique_ptr<Usb2000Device> device_; // reader thread only
    std::uint32_t sequence_ = 0;            // reader thread only
    LiveQueue<SpectrumSample> queue_;
    std::uint64_t dropped_ = 0; // reader thread only
    std::thread thread_;
};

} // namespace

TransportOpener libusbUsb2000Opener(std::string serial)
{
    return [serial = std::move(serial)] {
        return openLibusbTransport(usb2000::kVendorId, usb2000::kProductId, 0, 0, serial);
    };
}

std::unique_ptr<SpectrometerSource>
makeUsb2000Source(TransportOpener opener, const Clock& clock, Usb2000SourceOptions options)
{
    return std::make_unique<Usb2000Source>(std::move(opener), clock, std::move(options));
}

} // namespace replica::hal::spectrometer
