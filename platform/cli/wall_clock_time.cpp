// Session seconds, times of day and ISO 8601 instants for 'replay --from/--to' (see the header).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <vector>

#include <fmt/format.h>

#include <platform/cli/wall_clock_time.h>

// The helpers live in a namespace of their own: the unity build puts this file beside others.
namespace replica::platform::wall_clock {

std::int64_t daysFromCivilImpl(int year, int month, int day);
std::string isoLocalImpl(std::int64_t unixNs);
std::string isoUtcImpl(std::int64_t unixNs);

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;
constexpr std::int64_t kNsPerDay = 86'400 * kNsPerS;
// The span is printed to the millisecond: an instant within half of one of its ends is inside.
constexpr std::int64_t kEdgeSlackNs = 500'000;

const char* const kForms = "give session seconds (1234.5), a time of day (14:32:05, 14:32:05.25) "
                           "or an ISO 8601 date and time (2026-12-06T14:32:05Z, "
                           "2026-12-06T14:32:05+01:00)";

std::int64_t floorDiv(std::int64_t a, std::int64_t b)
{
    return a / b - ((a % b != 0) && ((a < 0) != (b < 0)) ? 1 : 0);
}

bool leapYear(int y)
{
    return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
}

int daysInMonth(int y, int m)
{
    static constexpr int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    return m == 2 && leapYear(y) ? 29 : kDays[m - 1];
}

// Reads exactly 'n' decimal digits at s[pos]; advances pos.
std::optional<int> digits(std::string_view s, std::size_t& pos, std::size_t n)
{
    if (pos + n > s.size()) {
        return std::nullopt;
    }
    int v = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const char c = s[pos + i];
        if (std::isdigit(static_cast<unsigned char>(c)) == 0) {
            return std::nullopt;
        }
        v = v * 10 + (c - '0');
    }
    pos += n;
    return v;
}

Error bad(std::string_view text, const std::string& why)
{
    return Error{ErrorCode::InvalidArgument, fmt::format("'{}': {}", text, why)};
}

// HH:MM[:SS[.fff]] at s[pos] (advances pos): nanoseconds since 00:00.
Expected<std::int64_t> timeOfDay(std::string_view text, std::string_view s, std::size_t& pos)
{
    const auto h = digits(s, pos, 2);
    const bool colon = h && pos < s.size() && s[pos] == ':';
    pos += colon ? 1 : 0;
    const auto m = colon ? digits(s, pos, 2) : std::nullopt;
    if (!m) {
        return tl::unexpected(bad(text, fmt::format("not a time of day (HH:MM:SS); {}", kForms)));
    }
    std::optional<int> sec = 0;
    std::int64_t fracNs = 0;
    if (pos < s.size() && s[pos] == ':') {
        ++pos;
        sec = digits(s, pos, 2);
        if (sec && pos < s.size() && (s[pos] == '.' || s[pos] == ',')) {
            ++pos;
            std::int64_t scale = kNsPerS;
            const std::size_t first = pos;
            while (pos < s.size() && std::isdigit(static_cast<unsigned char>(s[pos])) != 0) {
                scale /= 10; // digits past the nanosecond are read and dropped
                fracNs += scale * (s[pos] - '0');
                ++pos;
            }
            sec = pos > first ? sec : std::nullopt;
        }
    }
    if (!sec) {
        return tl::unexpected(bad(text, fmt::format("seconds as SS or SS.fff; {}", kForms)));
    }
    if (*h == 24 && *m == 0 && *sec == 0 && fracNs == 0) {
        return tl::unexpected(bad(text, "24:00 is the end of a day: give 00:00:00 of the next day "
                                        "(an ISO 8601 date and time says which)"));
    }
    if (*h > 23 || *m > 59) {
        return tl::unexpected(bad(text, "hours run 00-23 and minutes 00-59"));
    }
    if (*sec == 60) {
        return tl::unexpected(bad(text,
                                  "a leap second: the recording's clock (Unix time) has none; "
                                  "give :59.999 or the next minute's :00"));
    }
    if (*sec > 59) {
        return tl::unexpected(bad(text, "seconds run 00-59"));
    }
    return (static_cast<std::int64_t>(*h) * 3600 + *m * 60 + *sec) * kNsPerS + fracNs;
}

Expected<TimeArg> sessionSeconds(std::string_view text)
{
    const std::string s(text);
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() ||
        std::isspace(static_cast<unsigned char>(s[0]))) {
        return tl::unexpected(bad(text, fmt::format("not a time; {}", kForms)));
    }
    if (!std::isfinite(v) || v < 0.0 || v > 1e9) {
        return tl::unexpected(bad(text, "session seconds run from 0 to 1e9"));
    }
    TimeArg a;
    a.form = TimeArg::Form::SessionSeconds;
    a.seconds = v;
    return a;
}

// YYYY-MM-DDTHH:MM:SS[.fff][Z|+HH:MM|-HH:MM|+HHMM|+HH].
Expected<TimeArg> isoDateTime(std::string_view text)
{
    std::size_t pos = 0;
    const auto y = digits(text, pos, 4);
    const bool d1 = y && pos < text.size() && text[pos++] == '-';
    const auto mo = d1 ? digits(text, pos, 2) : std::nullopt;
    const bool d2 = mo && pos < text.size() && text[pos++] == '-';
    const auto d = d2 ? digits(text, pos, 2) : std::nullopt;
    if (!d || pos >= text.size() || (text[pos] != 'T' && text[pos] != 't')) {
        return tl::unexpected(bad(text, fmt::format("not an ISO 8601 date and time "
                                                    "(YYYY-MM-DDTHH:MM:SS); {}",
                                                    kForms)));
    }
    ++pos;
    if (*mo < 1 || *mo > 12 || *d < 1 || *d > daysInMonth(*y, *mo)) {
        return tl::unexpected(
                bad(text, fmt::format("{:04d}-{:02d} has no day {:02d}", *y, *mo, *d)));
    }
    auto ns = timeOfDay(text, text, pos);
    if (!ns) {
        return tl::unexpected(ns.error());
    }
    TimeArg a;
    if (pos == text.size()) {
        a.form = TimeArg::Form::LocalDateTime;
        a.year = *y;
        a.month = *mo;
        a.day = *d;
        a.nsOfDay = *ns;
        return a;
    }
    std::int64_t offsetMin = 0;
    if (text[pos] == 'Z' || text[pos] == 'z') {
        ++pos;
    } else if (text[pos] == '+' || text[pos] == '-') {
        const int sign = text[pos++] == '-' ? -1 : 1;
        const auto oh = digits(text, pos, 2);
        const bool colon = pos < text.size() && text[pos] == ':';
        pos += colon ? 1 : 0;
        const auto om = pos < text.size() || colon ? digits(text, pos, 2) : std::optional<int>(0);
        if (!oh || !om || *oh > 23 || *om > 59) {
            return tl::unexpected(bad(text, "the offset is +HH:MM or -HH:MM (hours 00-23)"));
        }
        offsetMin = sign * (*oh * 60 + *om);
    }
    if (pos != text.size()) {
        return tl::unexpected(bad(text, fmt::format("unexpected '{}' after the time: end with Z, "
                                                    "+HH:MM, -HH:MM or nothing (local time)",
                                                    text.substr(pos))));
    }
    a.form = TimeArg::Form::Instant;
    a.unixNs = daysFromCivilImpl(*y, *mo, *d) * kNsPerDay + *ns - offsetMin * 60 * kNsPerS;
    return a;
}

struct Civil {
    int year = 0, month = 0, day = 0;
};

Civil localDate(std::int64_t unixNs)
{
    const std::time_t secs = static_cast<std::time_t>(floorDiv(unixNs, kNsPerS));
    std::tm tm{};
    ::localtime_r(&secs, &tm);
    return {tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday};
}

Civil nextDay(Civil c)
{
    if (++c.day > daysInMonth(c.year, c.month)) {
        c.day = 1;
        if (++c.month > 12) {
            c.month = 1;
            ++c.year;
        }
    }
    return c;
}

// Every instant that reads as this local date and time (none in a DST gap, two in the hour a DST
// change repeats).
std::vector<std::int64_t> localInstants(Civil c, std::int64_t nsOfDay)
{
    std::vector<std::int64_t> out;
    const auto secOfDay = static_cast<int>(nsOfDay / kNsPerS);
    for (const int dst : {0, 1}) {
        std::tm tm{};
        tm.tm_year = c.year - 1900;
        tm.tm_mon = c.month - 1;
        tm.tm_mday = c.day;
        tm.tm_hour = secOfDay / 3600;
        tm.tm_min = secOfDay / 60 % 60;
        tm.tm_sec = secOfDay % 60;
        tm.tm_isdst = dst;
        const std::time_t t = std::mktime(&tm);
        std::tm back{};
        if (t == static_cast<std::time_t>(-1) || ::localtime_r(&t, &back) == nullptr) {
            continue;
        }
        // mktime normalises a time that does not exist, or a DST flag the zone does not have
        // then: only a time that reads back the same is one.
        if (back.tm_year != c.year - 1900 || back.tm_mon != c.month - 1 || back.tm_mday != c.day ||
            back.tm_hour * 3600 + back.tm_min * 60 + back.tm_sec != secOfDay) {
            continue;
        }
        const std::int64_t ns = static_cast<std::int64_t>(t) * kNsPerS + nsOfDay % kNsPerS;
        if (out.empty() || out.front() != ns) {
            out.push_back(ns);
        }
    }
    return out;
}

// The local time zone's abbreviation at 'unixNs', and where it comes from.
std::string zoneName(std::int64_t unixNs)
{
    const std::time_t secs = static_cast<std::time_t>(floorDiv(unixNs, kNsPerS));
    std::tm tm{};
    ::localtime_r(&secs, &tm);
    const char* tz = std::getenv("TZ");
    return fmt::format("{}{}", tm.tm_zone != nullptr ? tm.tm_zone : "?",
                       tz != nullptr && *tz != '\0' ? fmt::format(", TZ={}", tz)
                                                    : std::string(", the machine's zone"));
}

std::string spanText(const RecordingSpan& span)
{
    const std::int64_t end = span.wallStartNs + span.lastNs;
    return fmt::format("the recording spans session seconds 0 to {:.3f}, {} to {} ({} to {})",
                       static_cast<double>(span.lastNs) * 1e-9, isoLocalImpl(span.wallStartNs),
                       isoLocalImpl(end), isoUtcImpl(span.wallStartNs), isoUtcImpl(end));
}

} // namespace

std::int64_t daysFromCivilImpl(int year, int month, int day)
{
    // H. Hinnant's days_from_civil: proleptic Gregorian, eras of 400 years.
    const std::int64_t y = static_cast<std::int64_t>(year) - (month <= 2 ? 1 : 0);
    const std::int64_t era = floorDiv(y, 400);
    const std::int64_t yoe = y - era * 400;
    const std::int64_t mp = (month + 9) % 12;
    const std::int64_t doy = (153 * mp + 2) / 5 + day - 1;
    const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    return era * 146097 + doe - 719468;
}

Expected<TimeArg> parseImpl(std::string_view text)
{
    if (text.find(':') == std::string_view::npos) {
        return sessionSeconds(text);
    }
    if (text.size() > 10 && text[4] == '-') {
        return isoDateTime(text);
    }
    std::size_t pos = 0;
    auto ns = timeOfDay(text, text, pos);
    if (!ns) {
        return tl::unexpected(ns.error());
    }
    if (pos != text.size()) {
        return tl::unexpected(bad(text, fmt::format("unexpected '{}' after the time of day; a "
                                                    "zone needs the date too "
                                                    "(2026-12-06T14:32:05+01:00)",
                                                    text.substr(pos))));
    }
    TimeArg a;
    a.form = TimeArg::Form::TimeOfDay;
    a.nsOfDay = *ns;
    return a;
}

Expected<ResolvedTime> resolveImpl(const std::string& option,
                                   const std::string& text,
                                   const TimeArg& arg,
                                   const RecordingSpan& span)
{
    const auto fail = [&](const std::string& why) {
        return makeError(ErrorCode::InvalidArgument, fmt::format("{} {}: {}", option, text, why));
    };
    if (span.wallStartNs <= 0) {
        return fail("the recording holds no wall-clock start: give session seconds");
    }
    const std::int64_t start = span.wallStartNs;
    const std::int64_t end = span.wallStartNs + span.lastNs;
    const auto inside = [&](std::int64_t ns) {
        return ns >= start - kEdgeSlackNs && ns <= end + kEdgeSlackNs;
    };
    std::vector<std::int64_t> named; // every instant the argument names
    if (arg.form == TimeArg::Form::Instant) {
        named.push_back(arg.unixNs);
    } else if (arg.form == TimeArg::Form::LocalDateTime) {
        named = localInstants({arg.year, arg.month, arg.day}, arg.nsOfDay);
    } else if (arg.form == TimeArg::Form::TimeOfDay) {
        // Each local day the recording touches (at most three are looked at: a longer recording
        // names every time of day twice anyway).
        Civil c = localDate(start);
        const Civil last = localDate(end);
        for (int i = 0; i < 3; ++i, c = nextDay(c)) {
            for (const auto ns : localInstants(c, arg.nsOfDay)) {
                named.push_back(ns);
            }
            if (c.year == last.year && c.month == last.month && c.day == last.day) {
                break;
            }
        }
    } else {
        return fail("session seconds are not a wall-clock time");
    }
    std::sort(named.begin(), named.end());
    std::vector<std::int64_t> in;
    for (const auto ns : named) {
        if (inside(ns)) {
            in.push_back(ns);
        }
    }
    const std::string zone = arg.form == TimeArg::Form::Instant
                                     ? std::string()
                                     : fmt::format(", local time {}", zoneName(start));
    if (in.size() > 1) {
        return fail(fmt::format("names both {} and {}{}: give an ISO 8601 date and time with "
                                "its offset; {}",
                                isoLocalImpl(in[0]), isoLocalImpl(in[1]), zone, spanText(span)));
    }
    if (in.empty() && named.empty()) {
        return fail(
                fmt::format("no such time on the recording's days{}; {}", zone, spanText(span)));
    }
    if (in.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{} {} ({}{}) is outside the recording: {}", option, text,
                                     isoLocalImpl(named[0]), zone, spanText(span)));
    }
    ResolvedTime r;
    r.unixNs = in.front();
    // A division, not a product with 1e-9: 1925250000000 ns is exactly 1925.25 s.
    r.sessionS = static_cast<double>(std::max<std::int64_t>(r.unixNs - start, 0)) / 1e9;
    return r;
}

std::string isoLocalImpl(std::int64_t unixNs)
{
    const std::time_t secs = static_cast<std::time_t>(floorDiv(unixNs, kNsPerS));
    std::tm tm{};
    if (::localtime_r(&secs, &tm) == nullptr) {
        return "unknown";
    }
    const long off = tm.tm_gmtoff;
    const long aoff = off < 0 ? -off : off;
    return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:02d}.{:03d}{}{:02d}:{:02d}",
                       tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min,
                       tm.tm_sec, static_cast<int>(floorDiv(unixNs, 1'000'000) % 1000),
                       off < 0 ? '-' : '+', aoff / 3600, aoff / 60 % 60);
}

std::string isoUtcImpl(std::int64_t unixNs)
{
    const std::time_t secs = static_cast<std::time_t>(floorDiv(unixNs, kNsPerS));
    std::tm tm{};
    if (::gmtime_r(&secs, &tm) == nullptr) {
        return "unknown";
    }
    return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:02d}.{:03d}Z", tm.tm_year + 1900,
                       tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                       static_cast<int>(floorDiv(unixNs, 1'000'000) % 1000));
}

} // namespace replica::platform::wall_clock

namespace replica::platform {

std::int64_t daysFromCivil(int year, int month, int day)
{
    return wall_clock::daysFromCivilImpl(year, month, day);
}

Expected<TimeArg> parseTimeArg(std::string_view text)
{
    return wall_clock::parseImpl(text);
}

Expected<ResolvedTime> resolveWallClock(const std::string& option,
                                        const std::string& text,
                                        const TimeArg& arg,
                                        const RecordingSpan& span)
{
    return wall_clock::resolveImpl(option, text, arg, span);
}

std::string isoLocal(std::int64_t unixNs)
{
    return wall_clock::isoLocalImpl(unixNs);
}

std::string isoUtcMs(std::int64_t unixNs)
{
    return wall_clock::isoUtcImpl(unixNs);
}

} // namespace replica::platform
