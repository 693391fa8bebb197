// A byte-level fake of a HID eye/head tracker (usage page 0x12) behind the HidDevice seam. It is
// built from a report descriptor and raw report bytes written by hand for that descriptor, and
// behaves as the usage page says the firmware does: no tracking data until the host writes a
// Device Mode Request. The fake knows its own report layout (the test author's byte offsets), not
// the parser's, so the driver is tested against the descriptor's meaning.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <hal/tracker/hid_device.h>

namespace replica::tests {

struct FakeHidTrackerState {
    std::vector<std::uint8_t> descriptor;
    bool descriptorUnreadable = false;
    // Feature reports as the device answers them, ID byte first (0 when not numbered).
    std::map<std::uint8_t, std::vector<std::uint8_t>> features;
    // Where the firmware keeps its mode: this feature report, this byte (counting the ID byte).
    std::uint8_t modeReportId = 0;
    std::size_t modeByte = 1;
    // Input reports to deliver once a mode is set, as hidapi would return them.
    std::deque<std::vector<std::uint8_t>> inputs;

    // Observations.
    std::vector<std::vector<std::uint8_t>> sentFeatures;
    int opens = 0;

    bool unplugged = false;
    std::mutex mutex;

    int mode() const
    {
        const auto it = features.find(modeReportId);
        return it == features.end() || it->second.size() <= modeByte ? 0 : it->second[modeByte];
    }
};

class FakeHidTracker final : public hal::hid::HidDevice
{
public:
    explicit FakeHidTracker(std::shared_ptr<FakeHidTrackerState> s) : s_(std::move(s)) {}

    Expected<std::vector<std::uint8_t>> reportDescriptor() override
    {
        std::lock_guard lock(s_->mutex);
        if (s_->descriptorUnreadable) {
            return makeError(ErrorCode::Io, "fake: report_descriptor unreadable");
        }
        return s_->descriptor;
    }

    hal::hid::HidResult readInput(std::span<std::uint8_t> buffer, int) override
    {
        using hal::hid::HidStatus;
        {
            std::lock_guard lock(s_->mutex);
            if (s_->unplugged) {
                return {HidStatus::Gone, 0};
            }
            if (s_->mode() != 0 && !s_->inputs.empty()) {
                auto r = std::move(s_->inputs.front());
                s_->inputs.pop_front();
                const std::size_t n = std::min(r.size(), buffer.size());
                std::copy_n(r.begin(), n, buffer.begin());
                return {HidStatus::Ok, n};
            }
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1)); // a real read would wait
        return {HidStatus::Timeout, 0};
    }

    hal::hid::HidResult getFeature(std::uint8_t id, std::span<std::uint8_t> buffer) override
    {
        using hal::hid::HidStatus;
        std::lock_guard lock(s_->mutex);
        if (s_->unplugged) {
            return {HidStatus::Gone, 0};
        }
        const auto it = s_->features.find(id);
        if (it == s_->features.end()) {
            return {HidStatus::Io, 0}; // the device stalls an unknown report
        }
        const std::size_t n = std::min(it->second.size(), buffer.size());
        std::copy_n(it->second.begin(), n, buffer.begin());
        return {HidStatus::Ok, n};
    }

    hal::hid::HidStatus sendFeature(std::span<const std::uint8_t> report) override
    {
        using hal::hid::HidStatus;
        std::lock_guard lock(s_->mutex);
        if (s_->unplugged) {
            return HidStatus::Gone;
        }
        if (report.empty()) {
            return HidStatus::Io;
        }
        s_->sentFeatures.emplace_back(report.begin(), report.end());
        auto it = s_->features.find(report[0]);
        if (it == s_->features.end() || it->second.size() != report.size()) {
            return HidStatus::Io; // wrong ID or length: the device stalls the request
        }
        it->second.assign(report.begin(), report.end());
        return HidStatus::Ok;
    }

    std::string describe() const override { return "fake hidraw (2104:0127)"; }

private:
    std::shared_ptr<FakeHidTrackerState> s_;
};

} // namespace replica::tests
