// What the state stage did not use, said in the log: the spectra, tilt readings and poses an
// estimator refused (saturated, an impossible integration time, |g| far from 1 g, gravity along
// the hinge, a pose no head can take), each device's first at once and then at most one line per
// interval with how many and why the last, and the viewer leaving and coming back into the
// tracker's view. The frame holds the last good value meanwhile (state/): without these lines a
// panel could show a held tilt 150 degrees off, or a run could render no light at all, with
// nothing in the journal to say why.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <hal/log_limiter.h>

namespace replica::state {
class SceneEstimator;
}

namespace replica::platform {

struct LoopStats;

class RefusalLog
{
public:
    // After the state stage's update for the frame at tickNs (session time): logs what it
    // refused since the last call and counts it into stats.refused (device kind name -> count).
    void after(const state::SceneEstimator& estimator, std::int64_t tickNs, LoopStats& stats);

private:
    struct Device {
        std::uint64_t seen = 0; // the estimator's count at the last call
        hal::LogLimiter limiter;
    };
    // 'one' and 'many': the sample's name in the singular and the plural.
    void report(Device& d,
                std::uint64_t count,
                const std::string& kind,
                const char* one,
                const char* many,
                const std::string& why,
                const std::string& held,
                std::int64_t tickNs,
                LoopStats& stats);
    std::map<std::string, Device> devices_;
    Device weak_; // spectra too weak to tell a colour by: said at info
    std::optional<bool> inView_;
    std::int64_t outOfViewSinceNs_ = 0;
};

} // namespace replica::platform
