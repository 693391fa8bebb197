// Replay sources: return exactly the recorded samples, with their original timestamps and sequence
// numbers, whatever the playback speed.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <hal/sources.h>

namespace replica::hal {

template <typename Sample>
class ReplaySource final : public Source<Sample>
{
public:
    // samples must be in time order (as recorded).
    ReplaySource(DeviceInfo recorded, std::vector<Sample> samples)
        : info_(std::move(recorded)), samples_(std::move(samples))
    {
        info_.kind = SourceKind::Replay;
    }

    const DeviceInfo& info() const override { return info_; }
    LinkState state() const override { return LinkState::Connected; }

    void poll(std::int64_t untilNs, std::vector<Sample>& out) override
    {
        while (next_ < samples_.size() && samples_[next_].timestampNs <= untilNs) {
            out.push_back(samples_[next_]);
            ++next_;
        }
    }

private:
    DeviceInfo info_;
    std::vector<Sample> samples_;
    std::size_t next_ = 0;
};

} // namespace replica::hal
