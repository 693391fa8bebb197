// Area loggers and level parsing.
#include <cstdlib>
#include <mutex>
#include <sstream>

#include <spdlog/sinks/stdout_color_sinks.h>

#include <platform/logging.h>

namespace replica::platform {
namespace {

const char* const kAreas[] = {"hal.spectrometer", "hal.tracker", "hal.accel", "pipeline", "render",
                              "output",           "rec",         "loop",      "replica"};

std::mutex& registryMutex()
{
    static std::mutex m;
    return m;
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
            const auto level = spdlog::level::from_str(item);
            for (const char* area : kAreas) {
                logger(area)->set_level(level);
            }
        } else {
            logger(item.substr(0, eq))->set_level(spdlog::level::from_str(item.substr(eq + 1)));
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

void setupLogging(const std::string& spec)
{
    for (const char* area : kAreas) {
        logger(area);
    }
    applySpec(spec);
    if (const char* env = std::getenv("REPLICA_LOG"); env != nullptr) {
        applySpec(env);
    }
}

} // namespace replica::platform
