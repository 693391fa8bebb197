// A byte-level fake of the Ocean Optics USB2000+ behind the UsbTransport seam: it parses the
// command bytes as the device's firmware would and answers with the device's reply layouts, so
// the driver above is tested against the protocol, not against itself. Faults can be injected.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <hal/spectrometer/usb_transport.h>

namespace replica::tests {

struct FakeUsb2000State {
    std::map<int, std::string> eeprom{
            {0, "USB2+F00001"}, {1, "339.2"}, {2, "0.3797"}, {3, "-1.62e-05"},
            {4, "-1.3e-10"},    {6, "1.0"},   {7, "-2e-06"}, {14, "1"},
    };
    std::uint16_t saturation = 0; // slot 17; 0 = not programmed
    // Counts for the next spectrum given the integration time in effect when it was exposed.
    std::function<std::vector<std::uint16_t>(std::uint32_t integrationUs)> counts =
            [](std::uint32_t us) {
                return std::vector<std::uint16_t>(2048,
                                                  static_cast<std::uint16_t>(1000 + us / 1000));
            };

    // Device state as the firmware holds it.
    std::uint32_t integrationUs = 0;
    bool initialised = false;
    std::uint16_t triggerMode = 0xFFFF;

    // Observations.
    std::vector<std::vector<std::uint8_t>> commands; // every OUT transfer, verbatim
    int spectraServed = 0;
    int haltsCleared = 0;

    // Faults.
    bool unplugged = false;
    int badSyncOnce = 0;       // next N spectra end in a wrong sync byte
    int shortSpectrumOnce = 0; // next N spectra are cut short
    bool garbleSlotEcho = false;
};

class FakeUsb2000 final : public hal::spectrometer::UsbTransport
{
public:
    explicit FakeUsb2000(std::shared_ptr<FakeUsb2000State> s) : s_(std::move(s)) {}

    hal::spectrometer::UsbResult
    bulkWrite(std::uint8_t ep, std::span<const std::uint8_t> data, int) override
    {
        using hal::spectrometer::UsbStatus;
        if (s_->unplugged) {
            return {UsbStatus::Gone, 0};
        }
        if (ep != 0x01 || data.empty()) {
            return {UsbStatus::Stall, 0};
        }
        s_->commands.emplace_back(data.begin(), data.end());
        switch (data[0]) {
        case 0x01:
            s_->initialised = true;
            replies_.clear();
            spectra_.clear();
            break;
        case 0x02: {
            if (data.size() != 5) {
                return {UsbStatus::Stall, 0};
            }
            std::uint32_t us = 0;
            for (int i = 0; i < 4; ++i) {
                us |= static_cast<std::uint32_t>(data[1 + static_cast<std::size_t>(i)]) << (8 * i);
            }
            // The firmware silently ignores out-of-range values.
            if (us >= 1000 && us <= 655'350'000) {
                s_->integrationUs = us;
            }
            break;
        }
        case 0x05: {
            if (data.size() != 2) {
                return {UsbStatus::Stall, 0};
            }
            std::vector<std::uint8_t> r(17, 0);
            r[0] = 0x05;
            r[1] = s_->garbleSlotEcho ? static_cast<std::uint8_t>(data[1] + 1) : data[1];
            if (data[1] == 17) {
                r[6] = static_cast<std::uint8_t>(s_->saturation & 0xFF);
                r[7] = static_cast<std::uint8_t>(s_->saturation >> 8);
            } else if (auto it = s_->eeprom.find(data[1]); it != s_->eeprom.end()) {
                std::memcpy(r.data() + 2, it->second.data(),
                            std::min<std::size_t>(15, it->second.size()));
            }
            replies_.push_back(std::move(r));
            break;
        }
        case 0x09: {
            if (!s_->initialised) {
                return {UsbStatus::Io, 0};
            }
            // The exposure that was running when the integration time changed is what the first
            // spectrum after the change carries: model it as the previous value.
            const std::uint32_t exposed =
                    lastExposureUs_ == 0 ? s_->integrationUs : lastExposureUs_;
            lastExposureUs_ = s_->integrationUs;
            auto counts = s_->counts(exposed);
            std::vector<std::uint8_t> b(4097);
            for (std::size_t p = 0; p < 2048; ++p) {
                b[2 * p] = static_cast<std::uint8_t>(counts[p] & 0xFF);
                b[2 * p + 1] = static_cast<std::uint8_t>(counts[p] >> 8);
            }
            b[4096] = 0x69;
            if (s_->badSyncOnce > 0) {
                --s_->badSyncOnce;
                b[4096] = 0x00;
            }
            if (s_->shortSpectrumOnce > 0) {
                --s_->shortSpectrumOnce;
                b.resize(2048);
            }
            spectra_.push_back(std::move(b));
            break;
        }
        case 0x0A:
            if (data.size() != 3) {
                return {UsbStatus::Stall, 0};
            }
            s_->triggerMode = static_cast<std::uint16_t>(data[1] | (data[2] << 8));
            break;
        default:
            return {UsbStatus::Stall, 0};
        }
        return {UsbStatus::Ok, data.size()};
    }

    hal::spectrometer::UsbResult
    bulkRead(std::uint8_t ep, std::span<std::uint8_t> buffer, int) override
    {
        using hal::spectrometer::UsbStatus;
        if (s_->unplugged) {
            return {UsbStatus::Gone, 0};
        }
        auto& q = ep == 0x81 ? replies_ : spectra_;
        if ((ep != 0x81 && ep != 0x82) || q.empty()) {
            return {UsbStatus::Timeout, 0};
        }
        auto bytes = std::move(q.front());
        q.pop_front();
        if (bytes.size() > buffer.size()) {
            return {UsbStatus::Overflow, 0};
        }
        std::memcpy(buffer.data(), bytes.data(), bytes.size());
        if (ep == 0x82) {
            ++s_->spectraServed;
        }
        return {UsbStatus::Ok, bytes.size()};
    }

    hal::spectrometer::UsbStatus clearHalt(std::uint8_t) override
    {
        if (s_->unplugged) {
            return hal::spectrometer::UsbStatus::Gone;
        }
        ++s_->haltsCleared;
        return hal::spectrometer::UsbStatus::Ok;
    }

    std::string describe() const override { return "fake bus 9 address 9 (2457:101e)"; }

private:
    std::shared_ptr<FakeUsb2000State> s_;
    std::deque<std::vector<std::uint8_t>> replies_;
    std::deque<std::vector<std::uint8_t>> spectra_;
    std::uint32_t lastExposureUs_ = 0;
};

} // namespace replica::tests
