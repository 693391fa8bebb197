// 'replay --from/--to' as field staff give them: session seconds (1234.5), a time of day (14:32:05)
// or an ISO 8601 date and time (2026-12-06T14:32:05Z, ...+01:00, ...14:32:05.250), turned into
// seconds of session time against the recording's wall-clock start (SessionInfo::wallClockStartNs).
//
// The recording holds its start as Unix time (UTC) and no time zone, so a time of day, and an ISO
// date and time without Z or an offset, are read in the local time zone of the machine replaying
// (TZ=Europe/Berlin replica replay ... picks another). A time of day names that time on each local
// day the recording covers: it must fall inside the recording on exactly one of them (before the
// start on the start day it is the next day's only if the recording spans midnight; one that
// names two instants, a recording longer than a day or the hour a DST change repeats, is refused:
// give the ISO form). Unix time has no leap seconds, so 23:59:60 is refused, and so is 24:00 (say
// 00:00 of the next day).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <pipeline/base/expected.h>

namespace replica::platform {

struct TimeArg {
    enum class Form { SessionSeconds, TimeOfDay, LocalDateTime, Instant };
    Form form = Form::SessionSeconds;
    double seconds = 0.0;             // SessionSeconds
    std::int64_t nsOfDay = 0;         // TimeOfDay and LocalDateTime: since the day's 00:00
    int year = 0, month = 0, day = 0; // LocalDateTime
    std::int64_t unixNs = 0;          // Instant (Z or an offset)
};

// The argument's form and value; an error saying what is wrong and what the forms are.
Expected<TimeArg> parseTimeArg(std::string_view text);

// Unix time (ns) of a proleptic Gregorian date and time in UTC; the days since 1970-01-01.
std::int64_t daysFromCivil(int year, int month, int day);

// Where a wall-clock argument lands: the instant and its session second.
struct ResolvedTime {
    std::int64_t unixNs = 0;
    double sessionS = 0.0;
};

// The recording's span in both clocks: session time 0 to lastNs, at Unix time wallStartNs.
struct RecordingSpan {
    std::int64_t wallStartNs = 0;
    std::int64_t lastNs = 0;
};

// 'arg' (not SessionSeconds) against the recording, in the local time zone (TZ); an error (the
// option's name, the argument, the recording's span in both clocks) when it falls outside the
// recording, names no instant or two of them, or the recording has no wall-clock start.
Expected<ResolvedTime> resolveWallClock(const std::string& option,
                                        const std::string& text,
                                        const TimeArg& arg,
                                        const RecordingSpan& span);

// "2026-12-06T14:32:05.250+01:00": an instant in the local time zone, to the millisecond.
std::string isoLocal(std::int64_t unixNs);
// "2026-12-06T13:32:05.250Z".
std::string isoUtcMs(std::int64_t unixNs);

} // namespace replica::platform
