// 'replica probe': what live sensors this machine can see (and its GPIO chips, for the lamp
// selector), for field staff setting up or checking an appliance. Opens each device the way
// 'replica run --hal live' would, takes one reading, and says what to do about anything missing.
// With --config FILE: the devices that site file names, as the service's user (platform/cli/
// probe_site.h), and what the kiosk would do with each.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <hal/accel/iio_accel.h>
#include <hal/lamp/gpio_lamp_source.h>
#include <hal/lamp/libgpiod_lines.h>
#include <hal/spectrometer/libusb_transport.h>
#include <hal/spectrometer/usb2000_device.h>
#include <hal/spectrometer/usb2000_protocol.h>
#include <hal/tracker/hid_tracker_source.h>
#include <hal/tracker/hidapi_device.h>
#include <hal/tracker/opentrack_source.h>
#include <pipeline/scene/stand.h>
#include <platform/cli/commands.h>
#include <platform/cli/probe_site.h>
#include <platform/logging.h>
#include <recordings/device_kind.h>

namespace replica::platform {
namespace {

struct ProbeOptions {
    std::uint16_t trackerPort = 4242;
    std::string trackerBind = "127.0.0.1";
    double trackerWaitS = 2.0;
    std::string iioRoot = "/sys/bus/iio/devices";
    std::string accelName;
    std::string accelAxes = "x,y,z";
    std::string lampGpio; // CHIP:OFFSETS; empty = only list the GPIO chips
    std::string gpioDev = "/dev";
    std::string hidrawSysfs = "/sys/class/hidraw";
    bool json = false;
    std::string config; // a site file: its devices, as the service user, and the kiosk's plan
    std::optional<SiteConfig> site;
};

nlohmann::json probeSpectrometer()
{
    namespace usb2000 = hal::spectrometer::usb2000;
    auto transport =
            hal::spectrometer::openLibusbTransport(usb2000::kVendorId, usb2000::kProductId);
    if (!transport) {
        return {{"found", false}, {"error", transport.error().message}};
    }
    auto dev = hal::spectrometer::Usb2000Device::open(std::move(*transport));
    if (!dev) {
        return {{"found", true}, {"ok", false}, {"error", dev.error().message}};
    }
    const auto& cal = (*dev)->calibration();
    nlohmann::json j{{"found", true},
                     {"ok", true},
                     {"where", (*dev)->describe()},
                     {"serial", cal.serial},
                     {"wavelength_coeffs", cal.wavelengthCoeffs},
                     {"nonlinearity_order", cal.nonlinearityOrder},
                     {"saturation_counts", cal.saturationCounts}};
    auto s = (*dev)->readSpectrum();
    if (!s) {
        j["ok"] = false;
        j["error"] = s.error().message;
        return j;
    }
    std::uint16_t peak = 0;
    std::size_t at = 0;
    for (std::size_t i = 0; i < s->counts.size(); ++i) {
        if (s->counts[i] > peak) {
            peak = s->counts[i];
            at = i;
        }
    }
    const double p = static_cast<double>(at);
    j["integration_us"] = s->integrationTimeUs;
    j["peak_counts"] = peak;
    j["peak_nm"] = cal.wavelengthCoeffs[0] +
                   p * (cal.wavelengthCoeffs[1] +
                        p * (cal.wavelengthCoeffs[2] + p * cal.wavelengthCoeffs[3]));
    j["saturated"] = s->saturated;
    return j;
}

nlohmann::json probeAccel(const ProbeOptions& o)
{
    auto dev = hal::accel::IioAccelDevice::find(o.iioRoot, o.accelName);
    if (!dev) {
        return {{"found", false}, {"error", dev.error().message}};
    }
    nlohmann::json j{{"found", true}, {"name", dev->name()}, {"where", dev->dir().string()}};
    auto a = dev->read();
    if (!a) {
        j["ok"] = false;
        j["error"] = a.error().message;
        return j;
    }
    auto mapping = hal::accel::parseAxisMapping(o.accelAxes);
    if (!mapping) {
        j["ok"] = false;
        j["error"] = mapping.error().message;
        return j;
    }
    j["ok"] = true;
    j["reading_ms2"] = *a;
    const glm::dvec3 gp = hal::accel::gravityInPanel(*a, *mapping);
    j["gravity_panel_ms2"] = {gp.x, gp.y, gp.z};
    const double g = std::sqrt((*a)[0] * (*a)[0] + (*a)[1] * (*a)[1] + (*a)[2] * (*a)[2]);
    j["magnitude_ms2"] = g;
    if (auto tilt = pipeline::scene::tiltFromGravity(gp)) {
        j["tilt_deg"] = *tilt * 180.0 / 3.14159265358979323846;
    } else {
        j["tilt_deg"] = nullptr;
    }
    return j;
}

nlohmann::json probeTracker(const ProbeOptions& o)
{
    hal::SteadyClock clock;
    hal::tracker::OpentrackSourceOptions opt;
    opt.port = o.trackerPort;
    opt.bindAddress = o.trackerBind;
    auto src = hal::tracker::makeOpentrackSource(clock, opt);
    if (!src) {
        return {{"found", false}, {"error", src.error().message}};
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(o.trackerWaitS));
    std::vector<hal::PoseSample> got;
    (*src)->poll(clock.nowNs(), got);
    std::size_t tracked = 0;
    for (const auto& p : got) {
        tracked += p.tracked ? 1 : 0;
    }
    nlohmann::json j{{"listening", fmt::format("udp {}:{}", o.trackerBind, (*src)->boundPort())},
                     {"poses", tracked},
                     {"rejected_datagrams", (*src)->rejectedDatagrams()},
                     {"coalesced_datagrams", (*src)->coalescedDatagrams()},
                     {"found", tracked > 0}};
    if (tracked > 0) {
        const auto& last = got.back().tracked ? got.back() : got.front();
        j["eye_tracker_m"] = {last.eyeTrackerM.x, last.eyeTrackerM.y, last.eyeTrackerM.z};
        // The sender's rate: poses coalesced (more than one per 2 ms) were sent too.
        j["rate_hz"] = static_cast<double>(tracked +
                                           static_cast<std::size_t>((*src)->coalescedDatagrams())) /
                       o.trackerWaitS;
    } else {
        j["error"] = fmt::format("no head poses on UDP port {} in {} s: start opentrack with "
                                 "output 'UDP over network' to {}:{}",
                                 (*src)->boundPort(), o.trackerWaitS, o.trackerBind,
                                 (*src)->boundPort());
    }
    return j;
}

// HID eye/head trackers (usage page 0x12): every hidraw node whose report descriptor has one,
// each opened as 'replica run --tracker hid' would (configured, one report awaited).
nlohmann::json probeHidTrackers(const ProbeOptions& o)
{
    nlohmann::json list = nlohmann::json::array();
    for (const auto& n : hal::hid::listHidTrackers(o.hidrawSysfs, "/dev")) {
        nlohmann::json j{{"node", n.devNode},
                         {"name", n.name},
                         {"id", fmt::format("{:04x}:{:04x}", n.vendor, n.product)}};
        if (!n.error.empty()) {
            j["ok"] = false;
            j["error"] = n.error;
            list.push_back(j);
            continue;
        }
        j["layout"] = n.layout;
        hal::SteadyClock clock;
        auto dev = hal::hid::hidapiOpener(n.devNode, o.hidrawSysfs, "/dev")();
        if (!dev) {
            j["ok"] = false;
            j["error"] = dev.error().message;
            list.push_back(j);
            continue;
        }
        hal::tracker::HidTrackerOptions options;
        options.readTimeoutMs = 100;
        auto reader = hal::tracker::HidTrackerReader::open(std::move(*dev), clock, options);
        if (!reader) {
            j["ok"] = false;
            j["error"] = reader.error().message;
            list.push_back(j);
            continue;
        }
        const auto& d = reader->description();
        j["ok"] = true;
        j["status"] = d.status ? hal::hid::eht::statusName(*d.status) : "not reported";
        if (d.screenWidthM && d.screenHeightM) {
            j["calibrated_screen_m"] = {*d.screenWidthM, *d.screenHeightM};
        }
        if (d.samplingHz) {
            j["sampling_hz"] = *d.samplingHz;
        }
        j["mode_request"] = d.modeSent;
        for (int i = 0; i < 10; ++i) {
            auto s = reader->next();
            if (s && *s && (*s)->tracked) {
                const auto& e = (*s)->eyeTrackerM;
                j["eye_tracker_m"] = {e.x, e.y, e.z};
                break;
            }
        }
        list.push_back(j);
    }
    return list;
}

// The lamp selector: every GPIO chip this machine has, and with --lamp-gpio the configured lines
// opened as 'replica run --hal live' would and read once.
nlohmann::json probeLampSelector(const ProbeOptions& o)
{
    nlohmann::json chips = nlohmann::json::array();
    for (const auto& c : hal::lamp::listGpioChips(o.gpioDev)) {
        nlohmann::json cj{
                {"path", c.path}, {"name", c.name}, {"label", c.label}, {"lines", c.lines}};
        if (!c.error.empty()) {
            cj["error"] = c.error;
        }
        chips.push_back(cj);
    }
    nlohmann::json j{{"chips", chips}, {"configured", !o.lampGpio.empty()}};
    if (o.lampGpio.empty()) {
        return j;
    }
    auto spec = hal::lamp::parseGpioLineSpec(o.lampGpio);
    if (!spec) {
        j["found"] = false;
        j["error"] = spec.error().message;
        return j;
    }
    j["lines"] = hal::lamp::toString(*spec);
    auto lines = hal::lamp::libgpiodOpener()(*spec);
    if (!lines) {
        j["found"] = false;
        j["error"] = lines.error().message;
        return j;
    }
    j["found"] = true;
    j["where"] = (*lines)->describe();
    hal::SteadyClock clock;
    hal::lamp::LampSelectorReader reader(std::move(*lines), spec->offsets.size(), clock);
    auto s = reader.start(0);
    if (!s) {
        j["ok"] = false;
        j["error"] = s.error().message;
        return j;
    }
    j["ok"] = true;
    j["lamp"] = s->lamp;
    j["state"] = hal::lampStateName(s->lamp);
    std::vector<int> levels;
    for (std::uint32_t i = 0; i < s->lineCount; ++i) {
        levels.push_back((s->lineLevels >> i) & 1u ? 1 : 0);
    }
    j["levels"] = levels;
    return j;
}

// The report's entry as text, after the device's name: one line per entry.
std::string spectrometerText(const nlohmann::json& s)
{
    if (!s.value("ok", false)) {
        return fmt::format("MISSING: {}", s["error"].get<std::string>());
    }
    return fmt::format("USB2000+ serial {} at {}: peak {} counts at {:.1f} nm ({} us){}",
                       s["serial"].get<std::string>(), s["where"].get<std::string>(),
                       s["peak_counts"].get<int>(), s["peak_nm"].get<double>(),
                       s["integration_us"].get<std::uint32_t>(),
                       s["saturated"].get<bool>() ? ", SATURATED" : "");
}

std::string accelText(const nlohmann::json& a)
{
    if (!a.value("ok", false)) {
        return fmt::format("MISSING: {}", a["error"].get<std::string>());
    }
    return fmt::format("'{}' at {}: |g| = {:.2f} m/s^2, tilt {}", a["name"].get<std::string>(),
                       a["where"].get<std::string>(), a["magnitude_ms2"].get<double>(),
                       a["tilt_deg"].is_null()
                               ? std::string("undefined")
                               : fmt::format("{:.1f} deg", a["tilt_deg"].get<double>()));
}

std::string trackerText(const nlohmann::json& t)
{
    if (!t.value("found", false)) {
        return fmt::format("MISSING: {}", t["error"].get<std::string>());
    }
    return fmt::format("{} poses at {:.0f} Hz on {}", t["poses"].get<std::size_t>(),
                       t["rate_hz"].get<double>(), t["listening"].get<std::string>());
}

std::string hidTrackerText(const nlohmann::json& h)
{
    const std::string which = fmt::format("{} {} [{}]", h["node"].get<std::string>(),
                                          h["name"].get<std::string>(), h["id"].get<std::string>());
    if (!h.value("ok", false)) {
        return fmt::format("{}: UNUSABLE: {}", which, h["error"].get<std::string>());
    }
    return fmt::format("{}: {}; status {}{}", which, h["layout"].get<std::string>(),
                       h["status"].get<std::string>(),
                       h.contains("eye_tracker_m") ? "" : ", no tracked report yet");
}

std::string lampSelectorText(const nlohmann::json& lamp, const ProbeOptions& o)
{
    std::string chipList;
    for (const auto& c : lamp["chips"]) {
        chipList += fmt::format("{}{} [{}] {} lines{}", chipList.empty() ? "" : ", ",
                                c["name"].get<std::string>(), c["label"].get<std::string>(),
                                c["lines"].get<unsigned>(),
                                c.contains("error") ? " (cannot open: permission?)" : "");
    }
    if (chipList.empty()) {
        chipList = fmt::format("none under {}", o.gpioDev);
    }
    if (!lamp["configured"].get<bool>()) {
        return fmt::format("not configured (--lamp-gpio CHIP:OFFSETS); GPIO chips: {}", chipList);
    }
    if (!lamp.value("ok", false)) {
        return fmt::format("MISSING: {}; GPIO chips: {}", lamp["error"].get<std::string>(),
                           chipList);
    }
    std::string levels;
    for (const auto& v : lamp["levels"]) {
        levels += v.get<int>() != 0 ? '1' : '0';
    }
    const int l = lamp["lamp"].get<int>();
    return fmt::format("{}: {} (line levels {})", lamp["where"].get<std::string>(),
                       l >= 0 ? fmt::format("lamp {}", l) : lamp["state"].get<std::string>(),
                       levels);
}

// What probe knows of a device kind's live hardware: each of its report's entries (the first
// one the device's own, under the kind's display name; others, e.g. a listing, beside it), each
// made by opening the hardware as 'replica run --hal live' would, and one text line per entry.
struct ProbeEntry {
    std::string key;  // in the report
    std::string name; // before its text, for people
    std::function<nlohmann::json(const ProbeOptions&)> probe;
    std::function<std::string(const nlohmann::json&, const ProbeOptions&)> text;
    bool list = false; // a JSON array: a text line per element
};

// By device kind name (recordings::deviceKinds()); a kind with no live hardware has none.
const std::map<std::string, std::vector<ProbeEntry>>& deviceProbes()
{
    const auto plain = [](std::string (*f)(const nlohmann::json&)) {
        return [f](const nlohmann::json& j, const ProbeOptions&) { return f(j); };
    };
    static const std::map<std::string, std::vector<ProbeEntry>> probes{
            {"spectrometer",
             {{"spectrometer", "spectrometer",
               [](const ProbeOptions&) { return probeSpectrometer(); }, plain(spectrometerText)}}},
            {"tracker",
             {{"tracker", "tracker", probeTracker, plain(trackerText)},
              {"hid_trackers", "hid tracker", probeHidTrackers, plain(hidTrackerText), true}}},
            {"accel", {{"accelerometer", "accelerometer", probeAccel, plain(accelText)}}},
            {"lamp_selector",
             {{"lamp_selector", "lamp selector", probeLampSelector, lampSelectorText}}},
    };
    return probes;
}

// --config: the site file's device settings, except those given on the command line; its
// problems are printed (the good values are used). Empty when it cannot be read.
std::string applySite(ProbeOptions& o, const CLI::App& cmd)
{
    auto loaded = loadSiteConfig(o.config);
    if (!loaded) {
        return loaded.error().message;
    }
    for (const auto& p : loaded->problems) {
        logger("replica")->warn("{}", formatProblem(o.config, p));
    }
    const SiteConfig& s = loaded->config;
    const auto unless = [&cmd](const char* option, auto& field, const auto& value) {
        if (cmd.get_option(option)->count() == 0) {
            field = value;
        }
    };
    unless("--tracker-port", o.trackerPort, s.trackerPort);
    unless("--tracker-bind", o.trackerBind, s.trackerBind);
    unless("--iio-root", o.iioRoot, s.iioRoot);
    unless("--accel-name", o.accelName, s.accelName);
    unless("--accel-axes", o.accelAxes, s.accelAxes);
    unless("--lamp-gpio", o.lampGpio, s.lampGpio);
    o.site = s;
    return {};
}

int runProbe(const ProbeOptions& o)
{
    nlohmann::json report = nlohmann::json::object();
    std::optional<ProbeIdentity> identity;
    if (o.site) {
        identity = becomeServiceUser();
        report["probed_as"] = {{"user", identity->user},
                               {"groups", identity->groups},
                               {"service_user", identity->asServiceUser}};
        if (!o.json) {
            fmt::print("{:<15}{} (groups {})\n", "probed as", identity->note, identity->groups);
        }
    }
    std::vector<const ProbeEntry*> entries; // in the registry's order
    bool all = true;
    std::vector<std::string> missing;
    for (const auto* kind : recordings::deviceKinds()) {
        const auto it = deviceProbes().find(kind->name());
        if (it == deviceProbes().end()) {
            continue; // no live hardware to look for
        }
        for (const ProbeEntry& e : it->second) {
            report[e.key] = e.probe(o);
            entries.push_back(&e);
        }
        // The device's own entry: every run needs it; an optional one only where configured.
        const auto& d = report[it->second.front().key];
        const bool wanted = !kind->names().optional || d.value("configured", false);
        if (wanted && !(d.value("found", false) && d.value("ok", true))) {
            all = false;
            missing.push_back(kind->names().displayName);
        }
    }
    report["all_found"] = all;
    std::vector<std::string> plan;
    if (o.site) {
        plan = kioskPlan(*o.site, report);
        report["kiosk"] = plan;
    }
    // The report goes to standard output; a failing probe also says so in one line on standard
    // error, as every other failing command does.
    const auto summary = [&missing] {
        logger("replica")->error("probe: {} missing or not working (the report says why); "
                                 "connect it and probe again, or run with --hal sim",
                                 fmt::join(missing, ", "));
    };
    if (o.json) {
        std::cout << report.dump(2) << "\n";
        if (!all) {
            summary();
        }
        return all ? kExitOk : kExitFailure;
    }
    for (const ProbeEntry* e : entries) {
        const auto& j = report[e->key];
        if (!e->list) {
            fmt::print("{:<15}{}\n", e->name, e->text(j, o));
            continue;
        }
        for (const auto& item : j) {
            fmt::print("{:<15}{}\n", e->name, e->text(item, o));
        }
    }
    for (const auto& line : plan) {
        fmt::print("{:<15}{}\n", "kiosk", line);
    }
    if (!all) {
        std::fflush(stdout);
        summary();
    }
    return all ? kExitOk : kExitFailure;
}

} // namespace

void registerProbeCommand(CLI::App& app, int& exitCode)
{
    auto o = std::make_shared<ProbeOptions>();
    auto* cmd = app.add_subcommand(
            "probe", "check the live sensors: open each one, take a reading, say what is missing");
    cmd->add_option("--tracker-port", o->trackerPort, "UDP port opentrack sends to")
            ->capture_default_str();
    cmd->add_option("--tracker-bind", o->trackerBind, "address to listen on")
            ->capture_default_str();
    cmd->add_option("--tracker-wait", o->trackerWaitS, "seconds to listen for head poses")
            ->check(CLI::Range(0.0, 60.0))
            ->capture_default_str();
    cmd->add_option("--iio-root", o->iioRoot, "where IIO devices are listed")
            ->capture_default_str();
    cmd->add_option("--accel-name", o->accelName, "the accelerometer's IIO name");
    cmd->add_option("--accel-axes", o->accelAxes,
                    "sensor axis for each panel axis (x right, y up, z out of the screen)")
            ->capture_default_str();
    cmd->add_option("--lamp-gpio", o->lampGpio,
                    "the lamp selector's lines, CHIP:OFFSET,OFFSET,... (one per lamp, lamp "
                    "order); without it the GPIO chips are only listed");
    cmd->add_option("--gpio-dev", o->gpioDev, "where GPIO chips are listed")->capture_default_str();
    cmd->add_option("--hidraw-sysfs", o->hidrawSysfs,
                    "where hidraw devices are listed (HID eye/head trackers are found there)")
            ->capture_default_str();
    cmd->add_flag("--json", o->json, "print the report as JSON");
    cmd->add_option("--config", o->config,
                    "a site file (/etc/replica/replica.toml): probe the devices it names (options "
                    "given here win), as the service's user 'replica' when run as root, and say "
                    "what the kiosk would do with each")
            ->check(CLI::ExistingFile);
    cmd->callback([o, cmd, &exitCode] {
        if (!o->config.empty()) {
            if (const auto error = applySite(*o, *cmd); !error.empty()) {
                logger("replica")->error("probe: {}", error);
                exitCode = kExitFailure;
                return;
            }
        }
        exitCode = runProbe(*o);
    });
}

} // namespace replica::platform
