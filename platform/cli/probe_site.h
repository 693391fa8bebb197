// 'replica probe --config FILE': the devices a site file names, probed with the service's
// permissions, and what the kiosk would do with each.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <platform/site_config.h>

namespace replica::platform {

// Who the probe runs as. Run as root with the service user present, it becomes that user, with
// the groups replica.service gives it (its own and SupplementaryGroups=), so that each device is
// opened as the service would open it; otherwise it stays who it is and says so.
struct ProbeIdentity {
    std::string user;   // the user the probe now runs as
    std::string groups; // its groups, comma separated
    bool asServiceUser = false;
    std::string note; // one line for people
};
ProbeIdentity becomeServiceUser();

// One line per device and per site setting the kiosk acts on, saying what 'replica run --kiosk'
// would do with it given the probe's report (the keys of runProbe's JSON).
std::vector<std::string> kioskPlan(const SiteConfig& site, const nlohmann::json& report);

} // namespace replica::platform
