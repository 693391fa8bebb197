// The HAL's loggers: the platform registers one per device area ("hal.spectrometer", ...) with
// its pattern and level; without it (tests, tools) messages go to spdlog's default logger.
#pragma once

#include <memory>

#include <spdlog/spdlog.h>

namespace replica::hal {

inline std::shared_ptr<spdlog::logger> deviceLog(const char* area)
{
    auto l = spdlog::get(area);
    return l ? l : spdlog::default_logger();
}

} // namespace replica::hal
