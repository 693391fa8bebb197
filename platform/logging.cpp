// Area loggers and level parsing.
#include <cstdlib>
#include <mutex>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include <platform/logging.h>

namespace replica::platform {
namespace {

const char* const kAreas[] = {
        "hal.spectrometer", "hal.tracker", "hal.accel", "hal.lamp", "pipeline",
        "render",           "output",      "rec",       "loop",     "replica"};

std::mutex& registryMutex()
{
    static std::mutex m;
    return m;
}

// spdlog's own parser, which answers 'off' for any name it does not know: a typo must not switch
// every logger off.
std::optional<spdlog::level::level_enum> parseLevel(const std::string& name)
{
    const auto level = spdlog::level::from_str(name);
    if (level == spdlog::level::off && name != "off") {
        return std::nullopt;
    }
    return level;
}

void applySpec(const std::string& spec)
{
    std::istringstream in(spec);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item.empty()) {
            continue;
        }
        const auto eq = item.find('=');
        if (eq == std::string::npos) {
            const auto level = *parseLevel(item);
            for (const char* area : kAreas) {
                logger(area)->set_level(level);
            }
        } else {
            logger(item.substr(0, eq))->set_level(*parseLevel(item.substr(eq + 1)));
        }
    }
}

} // namespace

std::shared_ptr<spdlog::logger> logger(const std::string& area)
{
    std::lock_guard lock(registryMutex());
    if (auto existing = spdlog::get(area)) {
        return existing;
    }
    auto created = spdlog::stderr_color_mt(area);
    created->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
    return created;
}

std::string checkLogSpec(const std::string& spec)
{
    std::istringstream in(spec);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item.empty()) {
            continue;
        }
        const auto eq = item.find('=');
        const std::string level = eq == std::string::npos ? item : item.substr(eq + 1);
        if (eq == 0) {
            return fmt::format("'{}' names no logger; write 'name=level', e.g. hal.tracker=debug",
                               item);
        }
        if (!parseLevel(level)) {
            return fmt::format("unknown log level '{}'; use one of trace, debug, info, warn, "
                               "error, critical, off (for all loggers, or per logger as "
                               "'hal.tracker=debug,rec=info')",
                               level);
        }
    }
    return {};
}

void setupLogging(const std::string& spec, bool fromCommandLine)
{
    for (const char* area : kAreas) {
        logger(area);
    }
    // The default, then the environment, then the command line: the command line wins.
    applySpec("info");
    if (const char* env = std::getenv("REPLICA_LOG"); env != nullptr && checkLogSpec(env).empty()) {
        applySpec(env);
    }
    if (fromCommandLine) {
        applySpec(spec);
    }
}

} // namespace replica::platform
