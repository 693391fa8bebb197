// Text that came from a file or a device (a recording's software string, a device's model, a key
// name) shown on a terminal: control characters, which could be a terminal escape sequence that
// retitles the window, clears the screen or worse, are shown as \xNN, and a field can be cut.
// Every log line goes through it (platform/logging.cpp), as does inspect's report.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace replica {

// 's' with every control character (below 0x20, and 0x7f) as \xNN, cut after 'max' characters
// with "..." when longer. 'keepNewlines': '\n' stays (a log message of several lines).
inline std::string
printable(std::string_view s, std::size_t max = std::string_view::npos, bool keepNewlines = false)
{
    std::string out;
    out.reserve(s.size() < max ? s.size() : max);
    for (const char c : s.substr(0, max)) {
        const auto u = static_cast<unsigned char>(c);
        const bool control = (u < 0x20 || u == 0x7f) && !(keepNewlines && c == '\n');
        if (control) {
            out += fmt::format("\\x{:02x}", u);
        } else {
            out += c;
        }
    }
    return s.size() > max ? out + "..." : out;
}

} // namespace replica
