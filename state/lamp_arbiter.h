// How the booth's lamp selector switch and the spectrometer's classifier decide the light together
// (docs/architecture.md, "Lamp selector"): a turn of the switch takes effect at once, without the
// classifier's hysteresis wait, while the spectrometer confirms it; if the two disagree for longer
// than disagreeNs of sensor time, the spectrometer wins and one warning names a likely mis-wired
// switch. "off", "invalid", "lost" or no selector at all leave the classifier alone, as before.
// Every decision depends only on sample contents and timestamps, so replay reproduces it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <hal/samples.h>

namespace replica::state {

struct LampArbiterParams {
    // About twice what the classifier needs to confirm a change (3 spectra at 5 Hz after the
    // first exposure of the new light, about 0.8 s), and short enough that a wrong switch is not
    // believed for long (and shorter than the simulator's 2 s between lamp changes, so that
    // 'replica run --lamp-selector sim-miswired' shows the overruling).
    std::int64_t disagreeNs = 1'500'000'000;
};

// What the arbiter remembers (saved at the head of a rotated session file: scene_estimator.h).
struct LampArbiterState {
    int selected = -1;
    bool trusted = false;
    std::optional<std::int64_t> disagreeSinceNs;
    std::uint64_t overruled = 0;
    bool warned = false;
};

class LampArbiter
{
public:
    explicit LampArbiter(int lampCount, LampArbiterParams params = {});

    // A new selector sample. Returns the lamp to show from now on when the switch names one of
    // the booth's lamps; nothing when it does not (the classifier decides again).
    std::optional<int> onSelector(const hal::LampSample& s);

    // The classifier's answer (-1 = unknown) after a spectrum taken at tNs; returns the lamp to
    // show (-1 = direct-sensor mode): the selector's while it is trusted, else the classifier's.
    int onClassified(int classified, std::int64_t tNs);

    // The selector's lamp while it is trusted; -1 otherwise.
    int trustedLamp() const { return trusted_ ? selected_ : -1; }
    // How many times the spectrometer overruled the selector.
    std::uint64_t overruled() const { return overruled_; }
    // A warning to log, once per session, the first time the selector is overruled.
    std::optional<std::string> takeWarning();

    LampArbiterState state() const
    {
        return {selected_, trusted_, disagreeSinceNs_, overruled_, warned_};
    }
    // A selected lamp beyond the booth's is taken as none.
    void restore(const LampArbiterState& s);

private:
    int lampCount_;
    LampArbiterParams params_;
    int selected_ = -1;
    bool trusted_ = false;
    std::optional<std::int64_t> disagreeSinceNs_;
    std::uint64_t overruled_ = 0;
    std::optional<std::string> warning_;
    bool warned_ = false;
};

} // namespace replica::state
