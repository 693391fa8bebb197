// The lamp selector and the classifier, reconciled.
#include <fmt/format.h>
#include <state/lamp_arbiter.h>

namespace replica::state {

LampArbiter::LampArbiter(int lampCount, LampArbiterParams params)
    : lampCount_(lampCount), params_(params)
{}

std::optional<int> LampArbiter::onSelector(const hal::LampSample& s)
{
    disagreeSinceNs_.reset();
    if (s.lamp >= 0 && s.lamp < lampCount_) {
        selected_ = s.lamp;
        trusted_ = true;
        return selected_;
    }
    // Off, invalid, lost, or a line beyond the booth's lamps: the spectrometer alone decides.
    selected_ = -1;
    trusted_ = false;
    return std::nullopt;
}

int LampArbiter::onClassified(int classified, std::int64_t tNs)
{
    if (!trusted_) {
        return classified;
    }
    if (classified == selected_) {
        disagreeSinceNs_.reset();
        return selected_;
    }
    if (!disagreeSinceNs_) {
        disagreeSinceNs_ = tNs;
    }
    if (tNs - *disagreeSinceNs_ < params_.disagreeNs) {
        return selected_; // the classifier may still be confirming the change
    }
    trusted_ = false;
    ++overruled_;
    if (!warned_) {
        warned_ = true;
        warning_ = fmt::format(
                "the lamp selector says lamp {} but the spectrometer has seen {} for {:.1f} s: "
                "trusting the spectrometer. Is the selector mis-wired? Check that --lamp-gpio "
                "lists one line per lamp in the booth's lamp order",
                selected_,
                classified >= 0 ? fmt::format("lamp {}", classified)
                                : std::string("an unknown light"),
                static_cast<double>(tNs - *disagreeSinceNs_) * 1e-9);
    }
    return classified;
}

void LampArbiter::restore(const LampArbiterState& s)
{
    const bool valid = s.selected >= 0 && s.selected < lampCount_;
    selected_ = valid ? s.selected : -1;
    trusted_ = valid && s.trusted;
    disagreeSinceNs_ = s.disagreeSinceNs;
    overruled_ = s.overruled;
    warned_ = s.warned;
    warning_.reset();
}

std::optional<std::string> LampArbiter::takeWarning()
{
    auto w = std::move(warning_);
    warning_.reset();
    return w;
}

} // namespace replica::state
