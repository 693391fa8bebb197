// The site side of 'replica probe --config': the service user's permissions and the kiosk's plan.
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>
#include <grp.h>
#include <pwd.h>
#include <unistd.h>

#include <platform/cli/probe_site.h>

namespace replica::platform {
namespace {

// deploy/kiosk/replica.service: User=replica, SupplementaryGroups=video render plugdev.
constexpr const char* kServiceUser = "replica";
const char* const kServiceGroups[] = {"video", "render", "plugdev"};

std::string currentGroups()
{
    const group* primary = getgrgid(getegid());
    std::string out = primary != nullptr ? primary->gr_name : std::to_string(getegid());
    std::vector<gid_t> ids(static_cast<std::size_t>(std::max(getgroups(0, nullptr), 0)) + 1);
    const int n = getgroups(static_cast<int>(ids.size()), ids.data());
    ids.resize(static_cast<std::size_t>(std::max(n, 0)));
    for (const gid_t id : ids) {
        if (id == getegid()) {
            continue;
        }
        const group* g = getgrgid(id);
        out += fmt::format(",{}", g != nullptr ? std::string(g->gr_name) : std::to_string(id));
    }
    return out;
}

std::string currentUser()
{
    const passwd* pw = getpwuid(geteuid());
    return pw != nullptr ? pw->pw_name : std::to_string(geteuid());
}

// The groups systemd gives the service: the user's own (initgroups) and SupplementaryGroups=.
bool joinServiceGroups(const passwd& pw)
{
    if (initgroups(pw.pw_name, pw.pw_gid) != 0) {
        return false;
    }
    std::vector<gid_t> ids(static_cast<std::size_t>(std::max(getgroups(0, nullptr), 0)));
    ids.resize(static_cast<std::size_t>(
            std::max(getgroups(static_cast<int>(ids.size()), ids.data()), 0)));
    for (const char* name : kServiceGroups) {
        if (const group* g = getgrnam(name); g != nullptr) {
            ids.push_back(g->gr_gid);
        }
    }
    return setgroups(ids.size(), ids.data()) == 0;
}

// "can write" / "cannot write: Permission denied" for a path, as the current user.
std::string access(const std::string& path, int mode, const char* what)
{
    if (::access(path.c_str(), mode) == 0) {
        return fmt::format("can {}", what);
    }
    return fmt::format("cannot {}: {}", what, std::strerror(errno));
}

std::string missingPlan(const char* device, const std::string& meanwhile)
{
    return fmt::format("{}: missing: the kiosk starts without it, tries it again every second "
                       "and meanwhile shows {}",
                       device, meanwhile);
}

} // namespace

ProbeIdentity becomeServiceUser()
{
    ProbeIdentity id;
    const passwd* pw = getpwnam(kServiceUser);
    if (pw == nullptr) {
        id.note = fmt::format("no user '{}' on this machine (the package's postinst makes it): "
                              "probing as {}",
                              kServiceUser, currentUser());
    } else if (geteuid() != 0) {
        id.note = fmt::format("probing as {}, not as the service's user '{}': run 'sudo replica "
                              "probe --config FILE' to open each device with its permissions",
                              currentUser(), kServiceUser);
    } else {
        const passwd user = *pw;
        if (!joinServiceGroups(user) || setgid(user.pw_gid) != 0 || setuid(user.pw_uid) != 0) {
            id.note = fmt::format("could not become '{}' ({}): probing as {}", kServiceUser,
                                  std::strerror(errno), currentUser());
        } else {
            id.asServiceUser = true;
            id.note = fmt::format("probing as the service's user '{}'", kServiceUser);
        }
    }
    id.user = currentUser();
    id.groups = currentGroups();
    return id;
}

std::vector<std::string> kioskPlan(const SiteConfig& site, const nlohmann::json& report)
{
    std::vector<std::string> plan;
    if (site.hal != "live") {
        plan.push_back(fmt::format("hal = \"{}\": the kiosk opens no sensor{}", site.hal,
                                   site.hal == "replay" ? fmt::format(" and replays the samples "
                                                                      "of {}",
                                                                      site.replayFile)
                                                        : std::string(" (simulated sensors)")));
    } else {
        const auto ok = [&report](const char* key) {
            return report.contains(key) && report[key].value("found", false) &&
                   report[key].value("ok", true);
        };
        const std::string lamp =
                site.defaultLamp.empty()
                        ? std::string("black (no defaults.lamp)")
                        : fmt::format("the lamp '{}' (defaults.lamp)", site.defaultLamp);
        if (!ok("spectrometer")) {
            plan.push_back(missingPlan("spectrometer", lamp));
        } else if (!site.spectrometerSerial.empty() &&
                   report["spectrometer"].value("serial", "") != site.spectrometerSerial) {
            plan.push_back(fmt::format(
                    "spectrometer: the site file wants serial '{}', this one is '{}': the kiosk "
                    "leaves it Lost and shows {}",
                    site.spectrometerSerial, report["spectrometer"].value("serial", ""), lamp));
        } else {
            plan.push_back("spectrometer: the kiosk measures the light with it");
        }
        plan.push_back(ok("tracker") ? "tracker: the kiosk follows these head poses"
                                     : missingPlan("tracker", "the view from defaults.eye_m"));
        plan.push_back(ok("accelerometer")
                               ? "accelerometer: the kiosk reads the tilt from it"
                               : missingPlan("accelerometer", "the tilt defaults.tilt_deg"));
        plan.push_back(site.lampGpio.empty()
                               ? "lamp selector: none configured: the spectrometer alone "
                                 "decides the light"
                       : ok("lamp_selector") ? "lamp selector: the kiosk reads the lamp from it"
                                             : missingPlan("lamp selector", "what the "
                                                                            "spectrometer says"));
    }
    if (site.output == "kms") {
        plan.push_back(fmt::format("display {}: {}", site.kmsDevice,
                                   access(site.kmsDevice, R_OK | W_OK, "open it")));
    }
    if (site.recordingEnabled) {
        plan.push_back(fmt::format("sessions {}: {}", site.recordingDirectory,
                                   std::filesystem::is_directory(site.recordingDirectory)
                                           ? access(site.recordingDirectory, W_OK, "write")
                                           : std::string("no such folder: the kiosk cannot "
                                                         "record")));
    }
    return plan;
}

} // namespace replica::platform
