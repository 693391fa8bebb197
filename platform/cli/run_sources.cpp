// Where 'replica run' takes each device's samples from.
#include <initializer_list>
#include <utility>

#include <fmt/format.h>

#include <platform/cli/run_sources.h>
#include <platform/live_sources.h>
#include <platform/logging.h>
#include <recordings/recording.h>

namespace replica::platform::run_cli {

bool DeviceChoice::anyLive() const
{
    return spectrometer == "live" || tracker == "opentrack" || tracker == "hid" ||
           accel == "live" || lampSelector == "gpio";
}

bool DeviceChoice::anyReplay() const
{
    return spectrometer == "replay" || tracker == "replay" || accel == "replay" ||
           lampSelector == "replay";
}

bool DeviceChoice::anySim() const
{
    return spectrometer == "sim" || tracker == "sim" || accel == "sim" ||
           lampSelector.rfind("sim", 0) == 0;
}

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
    c.spectrometer = o.spectrometer.empty() ? o.hal : o.spectrometer;
    c.tracker = !o.tracker.empty() ? o.tracker : o.hal == "live" ? "opentrack" : o.hal;
    c.accel = o.accel.empty() ? o.hal : o.accel;
    c.lampSelector =
            !o.lampSelector.empty() ? o.lampSelector : (o.live.lampGpio.empty() ? "none" : "gpio");
    auto oneOf = [](const std::string& v, std::initializer_list<const char*> allowed) {
        for (const char* a : allowed) {
            if (v == a) {
                return true;
            }
        }
        return false;
    };
    if (!oneOf(c.spectrometer, {"live", "sim", "replay"}) ||
        !oneOf(c.tracker, {"opentrack", "hid", "sim", "replay"}) ||
        !oneOf(c.accel, {"live", "sim", "replay"}) ||
        !oneOf(c.lampSelector, {"none", "gpio", "sim", "sim-miswired", "replay"})) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("sources spectrometer={} tracker={} accel={} lamp_selector={}: "
                            "expected spectrometer and accel live|sim|replay, tracker "
                            "opentrack|hid|sim|replay, lamp_selector "
                            "none|gpio|sim|sim-miswired|replay",
                            c.spectrometer, c.tracker, c.accel, c.lampSelector));
    }
    if (c.lampSelector == "gpio" && o.live.lampGpio.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "--lamp-selector gpio needs --lamp-gpio CHIP:OFFSET,OFFSET,... (one line "
                         "per lamp)");
    }
    if (!o.live.lampGpio.empty() && c.lampSelector != "gpio") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--lamp-gpio {} and --lamp-selector {} contradict each other: "
                                     "the GPIO switch is --lamp-selector gpio",
                                     o.live.lampGpio, c.lampSelector));
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
    if (c.anySim()) {
        const bool simLamp = c.lampSelector == "sim" || c.lampSelector == "sim-miswired";
        auto made = makeSimSources(appliance, simLamp ? c.lampSelector : std::string("none"));
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
        if (c.lampSelector == "replay" && !replayed.lampSelector) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("--lamp-selector replay: {} has no lamp selector "
                                         "channel",
                                         o.replayFrom));
        }
    }
    Sources live;
    if (c.anyLive()) {
        LiveOptions lo = o.live;
        lo.spectrometer = c.spectrometer == "live";
        lo.tracker = c.tracker == "opentrack" || c.tracker == "hid" ? c.tracker : std::string();
        lo.accel = c.accel == "live";
        if (c.lampSelector != "gpio") {
            lo.lampGpio.clear();
        }
        auto made = makeLiveSources(liveClock, lo, appliance.booth.lights.size());
        if (!made) {
            return tl::unexpected(made.error());
        }
        live = std::move(*made);
    }
    auto pick = [](const std::string& kind, auto& l, auto& s, auto& r) {
        return kind == "sim" || kind.rfind("sim-", 0) == 0 ? std::move(s)
               : kind == "replay"                          ? std::move(r)
                                                           : std::move(l);
    };
    Sources out;
    out.spectrometer =
            pick(c.spectrometer, live.spectrometer, sim.spectrometer, replayed.spectrometer);
    out.tracker = pick(c.tracker, live.tracker, sim.tracker, replayed.tracker);
    out.accel = pick(c.accel, live.accel, sim.accel, replayed.accel);
    out.lampSelector = c.lampSelector == "none" ? nullptr
                                                : pick(c.lampSelector, live.lampSelector,
                                                       sim.lampSelector, replayed.lampSelector);
    // Say which devices do not come from the booth, so nobody mistakes a simulated one for it.
    if (c.anyLive()) {
        for (const auto& [name, kind] :
             {std::pair<const char*, const std::string&>{"spectrometer", c.spectrometer},
              {"tracker", c.tracker},
              {"accel", c.accel}}) {
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
