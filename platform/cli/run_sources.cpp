// Where 'replica run' takes each device's samples from.
#include <initializer_list>
#include <utility>

#include <fmt/format.h>

#include <platform/cli/run_sources.h>
#include <platform/live_sources.h>
#include <platform/logging.h>
#include <recordings/device_kind.h>
#include <recordings/recording.h>

namespace replica::platform::run_cli {

// The run's option that chooses a device kind's source: --spectrometer, --lamp-selector.
std::string deviceOption(const recordings::DeviceKindBase& kind)
{
    std::string s = kind.name();
    std::replace(s.begin(), s.end(), '_', '-');
    return s;
}

// Each device's source: --hal gives the default, --spectrometer/--tracker/--accel/--lamp-selector
// override it per device. Usage errors come back as InvalidArgument.
Expected<DeviceChoice> chooseDevices(const RunOptions& o)
{
    if (o.hal != "sim" && o.hal != "live" && o.hal != "replay") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--hal {}: expected 'sim' (built-in simulated sensors), "
                                     "'live' (USB2000+, opentrack, IIO accelerometer) or 'replay' "
                                     "(the samples of --replay-file)",
                                     o.hal));
    }
    DeviceChoice c;
    auto& spectrometer = c.from[recordings::spectrometerKind().name()];
    auto& tracker = c.from[recordings::trackerKind().name()];
    auto& accel = c.from[recordings::accelKind().name()];
    auto& lampSelector = c.from[recordings::lampSelectorKind().name()];
    spectrometer = o.spectrometer.empty() ? o.hal : o.spectrometer;
    tracker = !o.tracker.empty() ? o.tracker : o.hal == "live" ? "opentrack" : o.hal;
    accel = o.accel.empty() ? o.hal : o.accel;
    lampSelector =
            !o.lampSelector.empty() ? o.lampSelector : (o.live.lampGpio.empty() ? "none" : "gpio");
    auto oneOf = [](const std::string& v, std::initializer_list<const char*> allowed) {
        for (const char* a : allowed) {
            if (v == a) {
                return true;
            }
        }
        return false;
    };
    if (!oneOf(spectrometer, {"live", "sim", "replay"}) ||
        !oneOf(tracker, {"opentrack", "hid", "sim", "replay"}) ||
        !oneOf(accel, {"live", "sim", "replay"}) ||
        !oneOf(lampSelector, {"none", "gpio", "sim", "sim-miswired", "replay"})) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("sources spectrometer={} tracker={} accel={} lamp_selector={}: "
                            "expected spectrometer and accel live|sim|replay, tracker "
                            "opentrack|hid|sim|replay, lamp_selector "
                            "none|gpio|sim|sim-miswired|replay",
                            spectrometer, tracker, accel, lampSelector));
    }
    if (lampSelector == "gpio" && o.live.lampGpio.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "--lamp-selector gpio needs --lamp-gpio CHIP:OFFSET,OFFSET,... (one line "
                         "per lamp)");
    }
    if (!o.live.lampGpio.empty() && lampSelector != "gpio") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--lamp-gpio {} and --lamp-selector {} contradict each other: "
                                     "the GPIO switch is --lamp-selector gpio",
                                     o.live.lampGpio, lampSelector));
    }
    if (c.anyLive() && o.fast) {
        return makeError(ErrorCode::InvalidArgument,
                         "--fast needs simulated or replayed sensors: live sensors run on the "
                         "wall clock");
    }
    if (c.anyReplay() != !o.replayFrom.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         c.anyReplay() ? "a device set to 'replay' needs --replay-from "
                                         "RECORDING.mcap"
                                       : "--replay-from is for devices set to 'replay' (e.g. "
                                         "--tracker replay)");
    }
    return c;
}

Expected<Sources>
makeRunSources(const RunOptions& o, const Appliance& appliance, const hal::Clock& liveClock)
{
    auto choice = chooseDevices(o);
    if (!choice) {
        return tl::unexpected(choice.error());
    }
    const DeviceChoice& c = *choice;
    auto log = logger("replica");
    Sources sim;
    const std::string& lampFrom = c.of(recordings::lampSelectorKind());
    if (c.anySim()) {
        const bool simLamp = DeviceChoice::isSim(lampFrom);
        auto made = makeSimSources(appliance, simLamp ? lampFrom : std::string("none"));
        if (!made) {
            return tl::unexpected(made.error());
        }
        sim = std::move(*made);
    }
    Sources replayed;
    if (c.anyReplay()) {
        auto recording = recordings::readRecording(o.replayFrom);
        if (!recording) {
            return tl::unexpected(recording.error());
        }
        replayed = makeReplaySources(*recording);
        for (const auto* kind : recordings::deviceKinds()) {
            if (c.of(*kind) == "replay" && replayed.get(*kind) == nullptr) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("--{} replay: {} has no {} channel",
                                             deviceOption(*kind), o.replayFrom,
                                             kind->names().displayName));
            }
        }
    }
    Sources live;
    if (c.anyLive()) {
        LiveOptions lo = o.live;
        const std::string& trackerFrom = c.of(recordings::trackerKind());
        lo.spectrometer = c.of(recordings::spectrometerKind()) == "live";
        lo.tracker = DeviceChoice::isLive(trackerFrom) ? trackerFrom : std::string();
        lo.accel = c.of(recordings::accelKind()) == "live";
        if (lampFrom != "gpio") {
            lo.lampGpio.clear();
        }
        auto made = makeLiveSources(liveClock, lo, appliance.booth.lights.size());
        if (!made) {
            return tl::unexpected(made.error());
        }
        live = std::move(*made);
    }
    // Each device kind from where the choice says; "none": the run has no such device.
    Sources out;
    for (const auto* kind : recordings::deviceKinds()) {
        const std::string& from = c.of(*kind);
        Sources* src = from == "none"              ? nullptr
                       : DeviceChoice::isSim(from) ? &sim
                       : from == "replay"          ? &replayed
                                                   : &live;
        if (src != nullptr) {
            out.set(*kind, src->take(*kind));
        }
    }
    // Say which devices do not come from the booth, so nobody mistakes a simulated one for it.
    if (c.anyLive()) {
        for (const auto* device : recordings::deviceKinds()) {
            const std::string& name = device->name();
            const std::string& kind = c.of(*device);
            if (device->names().optional) {
                continue; // said only for the sensors every run has
            }
            if (kind == "sim" || kind == "replay") {
                log->warn("{} is {}: {}; the display follows it, not the booth's {}", name,
                          kind == "sim" ? "simulated" : "replayed",
                          kind == "sim" ? "the scripted scenario" : o.replayFrom, name);
            }
        }
    }
    return out;
}

} // namespace replica::platform::run_cli
