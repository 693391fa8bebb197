// Where 'replica run' takes each device's samples from.
#include <algorithm>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <platform/cli/run_sources.h>
#include <platform/live_sources.h>
#include <platform/logging.h>
#include <recordings/device_kind.h>
#include <recordings/recording.h>

namespace replica::platform::run_cli {

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
    const auto givenFor = [&o](const recordings::DeviceKindBase& kind) {
        const auto it = o.sources.find(kind.name());
        return it != o.sources.end() ? it->second : std::string();
    };
    DeviceChoice c;
    std::vector<std::string> given, expected;
    bool allKnown = true;
    for (const auto* kind : recordings::deviceKinds()) {
        const auto& names = kind->names();
        std::string from = givenFor(*kind);
        if (from.empty()) {
            // --hal's: the kind's live driver with --hal live; an optional kind none.
            from = names.optional ? "none" : o.hal == "live" ? names.liveSource : o.hal;
        }
        allKnown = allKnown && std::find(names.sources.begin(), names.sources.end(), from) !=
                                       names.sources.end();
        given.push_back(fmt::format("{}={}", kind->name(), from));
        expected.push_back(fmt::format("{} {}", kind->name(), fmt::join(names.sources, "|")));
        c.from[kind->name()] = std::move(from);
    }
    // The lamp selector's switch, when its lines are given: the GPIO one unless told otherwise.
    std::string& lampSelector = c.from[recordings::lampSelectorKind().name()];
    if (!o.live.lampGpio.empty() && givenFor(recordings::lampSelectorKind()).empty()) {
        lampSelector = "gpio";
    }
    if (!allKnown) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("sources {}: expected {}", fmt::join(given, " "),
                                     fmt::join(expected, ", ")));
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
        lo.devices.clear();
        for (const auto& [kind, from] : c.from) {
            if (DeviceChoice::isLive(from)) {
                lo.devices[kind] = from;
            }
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
