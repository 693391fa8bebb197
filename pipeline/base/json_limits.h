// Limits on JSON text before it is parsed (docs/limits.md): its size and its nesting depth,
// checked by one linear pass that allocates nothing, so that a deeply nested document cannot make
// a parser, a schema check or a printer do work that grows with the square of its depth.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include <fmt/format.h>

#include <pipeline/base/expected.h>

namespace replica {

// The deepest JSON Replica writes or ships is 5 levels (recordings/foxglove-layout.json); a
// recorded configuration is 3.
constexpr std::size_t kMaxJsonDepth = 32;
constexpr std::uintmax_t kMaxJsonTextBytes = 64u << 20; // as kMaxJsonBytes for a file

// The deepest nesting of arrays and objects in 'text' (brackets inside strings not counted).
inline std::size_t jsonDepth(std::string_view text)
{
    std::size_t depth = 0;
    std::size_t deepest = 0;
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') {
                ++i; // the escaped character, whatever it is
            } else if (c == '"') {
                inString = false;
            }
            continue;
        }
        if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            deepest = ++depth > deepest ? depth : deepest;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}

// Refuses JSON text over the size or depth limit, with one line naming 'where' (a file, or a
// recording and the message), the limit and the value.
inline Expected<void> checkJsonLimits(std::string_view text,
                                      std::string_view where,
                                      std::uintmax_t maxBytes = kMaxJsonTextBytes,
                                      std::size_t maxDepth = kMaxJsonDepth)
{
    if (text.size() > maxBytes) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: JSON of {} bytes, more than the limit of {}", where,
                                     text.size(), maxBytes));
    }
    if (const std::size_t depth = jsonDepth(text); depth > maxDepth) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: JSON nested {} levels deep, more than the limit of {}",
                                     where, depth, maxDepth));
    }
    return {};
}

} // namespace replica
