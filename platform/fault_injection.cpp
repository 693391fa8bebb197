// Fault-injecting wrappers around the sensor sources.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include <platform/fault_injection.h>

namespace replica::platform {
namespace {

template <typename Sample>
class FaultySource final : public hal::Source<Sample>
{
public:
    // mutate: changes a sample in place; false drops it.
    FaultySource(std::unique_ptr<hal::Source<Sample>> inner, std::function<bool(Sample&)> mutate)
        : inner_(std::move(inner)), mutate_(std::move(mutate))
    {}
    const hal::DeviceInfo& info() const override { return inner_->info(); }
    hal::LinkState state() const override { return inner_->state(); }
    void poll(std::int64_t untilNs, std::vector<Sample>& out) override
    {
        fresh_.clear();
        inner_->poll(untilNs, fresh_);
        for (auto& s : fresh_) {
            if (mutate_(s)) {
                out.push_back(std::move(s));
            }
        }
    }

private:
    std::unique_ptr<hal::Source<Sample>> inner_;
    std::function<bool(Sample&)> mutate_;
    std::vector<Sample> fresh_;
};

bool unplugged(const FaultPlan& plan, std::int64_t tNs)
{
    if (!(plan.unplugEveryS > 0.0) || !(plan.unplugForS > 0.0)) {
        return false;
    }
    const double t = static_cast<double>(tNs) * 1e-9;
    const double phase = std::fmod(t, plan.unplugEveryS);
    return phase >= plan.unplugEveryS - plan.unplugForS;
}

} // namespace

Expected<FaultPlan> parseFaultPlan(const std::string& spec)
{
    FaultPlan plan;
    std::stringstream in(spec);
    std::string item;
    while (std::getline(in, item, ',')) {
        const auto eq = item.find('=');
        const std::string key = item.substr(0, eq);
        const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
        const auto bad = [&] {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("--inject-faults {}: '{}' is not nan-pose=N, "
                                         "saturate=N or unplug=EVERY_S/FOR_S",
                                         spec, item));
        };
        try {
            if (key == "nan-pose") {
                plan.nanPoseEvery = static_cast<std::uint32_t>(std::stoul(value));
            } else if (key == "saturate") {
                plan.saturateEvery = static_cast<std::uint32_t>(std::stoul(value));
            } else if (key == "unplug") {
                const auto slash = value.find('/');
                if (slash == std::string::npos) {
                    return bad();
                }
                plan.unplugEveryS = std::stod(value.substr(0, slash));
                plan.unplugForS = std::stod(value.substr(slash + 1));
                if (!(plan.unplugEveryS > 0.0) || !(plan.unplugForS > 0.0) ||
                    !(plan.unplugForS < plan.unplugEveryS) || !std::isfinite(plan.unplugEveryS)) {
                    return bad();
                }
            } else {
                return bad();
            }
        } catch (const std::exception&) {
            return bad();
        }
    }
    return plan;
}

void injectFaults(Sources& sources, const FaultPlan& plan)
{
    if (!plan.any()) {
        return;
    }
    const auto& spectrometer = recordings::spectrometerKind();
    sources.set(spectrometer,
                std::make_unique<FaultySource<hal::SpectrumSample>>(
                        sources.take(spectrometer), [plan](hal::SpectrumSample& s) {
                            if (unplugged(plan, s.timestampNs)) {
                                return false;
                            }
                            if (plan.saturateEvery > 0 && s.sequence % plan.saturateEvery == 0) {
                                std::fill(s.counts.begin(), s.counts.end(), std::uint16_t{65535});
                                s.saturated = true;
                            }
                            return true;
                        }));
    const auto& tracker = recordings::trackerKind();
    sources.set(tracker,
                std::make_unique<FaultySource<hal::PoseSample>>(
                        sources.take(tracker), [plan](hal::PoseSample& s) {
                            if (unplugged(plan, s.timestampNs)) {
                                return false;
                            }
                            if (plan.nanPoseEvery > 0 && s.sequence % plan.nanPoseEvery == 0) {
                                s.eyeTrackerM.x = std::numeric_limits<double>::quiet_NaN();
                            }
                            return true;
                        }));
}

} // namespace replica::platform
