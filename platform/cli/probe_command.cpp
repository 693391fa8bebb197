// 'replica probe': what live sensors this machine can see, for field staff setting up or
// checking an appliance. Opens each device the way 'replica run --hal live' would, takes one
// reading, and says what to do about anything missing.
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <hal/accel/iio_accel.h>
#include <hal/spectrometer/libusb_transport.h>
#include <hal/spectrometer/usb2000_device.h>
#include <hal/spectrometer/usb2000_protocol.h>
#include <hal/tracker/opentrack_source.h>
#include <pipeline/scene/stand.h>
#include <platform/cli/commands.h>

namespace replica::platform {
namespace {

struct ProbeOptions {
    std::uint16_t trackerPort = 4242;
    std::string trackerBind = "127.0.0.1";
    double trackerWaitS = 2.0;
    std::string iioRoot = "/sys/bus/iio/devices";
    std::string accelName;
    std::string accelAxes = "x,y,z";
    bool json = false;
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
                     {"found", tracked > 0}};
    if (tracked > 0) {
        const auto& last = got.back().tracked ? got.back() : got.front();
        j["eye_tracker_m"] = {last.eyeTrackerM.x, last.eyeTrackerM.y, last.eyeTrackerM.z};
        j["rate_hz"] = static_cast<double>(tracked) / o.trackerWaitS;
    } else {
        j["error"] = fmt::format("no head poses on UDP port {} in {} s: start opentrack with "
                                 "output 'UDP over network' to {}:{}",
                                 (*src)->boundPort(), o.trackerWaitS, o.trackerBind,
                                 (*src)->boundPort());
    }
    return j;
}

int runProbe(const ProbeOptions& o)
{
    nlohmann::json report{{"spectrometer", probeSpectrometer()},
                          {"accelerometer", probeAccel(o)},
                          {"tracker", probeTracker(o)}};
    bool all = true;
    for (const char* k : {"spectrometer", "accelerometer", "tracker"}) {
        const auto& d = report[k];
        all = all && d.value("found", false) && d.value("ok", true);
    }
    report["all_found"] = all;
    if (o.json) {
        std::cout << report.dump(2) << "\n";
        return all ? kExitOk : kExitFailure;
    }
    const auto& s = report["spectrometer"];
    if (s.value("ok", false)) {
        fmt::print("spectrometer   USB2000+ serial {} at {}: peak {} counts at {:.1f} nm "
                   "({} us){}\n",
                   s["serial"].get<std::string>(), s["where"].get<std::string>(),
                   s["peak_counts"].get<int>(), s["peak_nm"].get<double>(),
                   s["integration_us"].get<std::uint32_t>(),
                   s["saturated"].get<bool>() ? ", SATURATED" : "");
    } else {
        fmt::print("spectrometer   MISSING: {}\n", s["error"].get<std::string>());
    }
    const auto& a = report["accelerometer"];
    if (a.value("ok", false)) {
        fmt::print("accelerometer  '{}' at {}: |g| = {:.2f} m/s^2, tilt {}\n",
                   a["name"].get<std::string>(), a["where"].get<std::string>(),
                   a["magnitude_ms2"].get<double>(),
                   a["tilt_deg"].is_null()
                           ? std::string("undefined")
                           : fmt::format("{:.1f} deg", a["tilt_deg"].get<double>()));
    } else {
        fmt::print("accelerometer  MISSING: {}\n", a["error"].get<std::string>());
    }
    const auto& t = report["tracker"];
    if (t.value("found", false)) {
        fmt::print("tracker        {} poses at {:.0f} Hz on {}\n", t["poses"].get<std::size_t>(),
                   t["rate_hz"].get<double>(), t["listening"].get<std::string>());
    } else {
        fmt::print("tracker        MISSING: {}\n", t["error"].get<std::string>());
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
    cmd->add_flag("--json", o->json, "print the report as JSON");
    cmd->callback([o, &exitCode] { exitCode = runProbe(*o); });
}

} // namespace replica::platform
