// replay --from/--to: session seconds, times of day and ISO 8601 instants against a recording's
// wall-clock start. Time zones are POSIX TZ strings (no tzdata needed).
#include <cstdlib>
#include <ctime>
#include <optional>
#include <string>

#include <platform/cli/wall_clock_time.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

constexpr std::int64_t kS = 1'000'000'000;
// 2026-12-06T14:32:05Z (python3: calendar.timegm).
constexpr std::int64_t k143205Z = 1796567525LL * kS;

using Form = TimeArg::Form;

class WallClockTime : public ::testing::Test
{
protected:
    void SetUp() override
    {
        if (const char* tz = std::getenv("TZ"); tz != nullptr) {
            saved_ = tz;
        }
        zone("UTC0");
    }
    void TearDown() override
    {
        if (saved_) {
            ::setenv("TZ", saved_->c_str(), 1);
        } else {
            ::unsetenv("TZ");
        }
        ::tzset();
    }
    static void zone(const char* tz)
    {
        ::setenv("TZ", tz, 1);
        ::tzset();
    }
    static TimeArg parse(const std::string& s)
    {
        auto a = parseTimeArg(s);
        EXPECT_TRUE(a.has_value()) << s << ": " << (a ? "" : a.error().message);
        return a ? *a : TimeArg{};
    }
    static std::string refused(const std::string& s)
    {
        auto a = parseTimeArg(s);
        EXPECT_FALSE(a.has_value()) << s << " was accepted";
        return a ? std::string() : a.error().message;
    }
    static Expected<ResolvedTime> resolve(const std::string& s, RecordingSpan span)
    {
        auto a = parseTimeArg(s);
        EXPECT_TRUE(a.has_value()) << s;
        if (!a) {
            return tl::unexpected(a.error());
        }
        return resolveWallClock("--from", s, *a, span);
    }

private:
    std::optional<std::string> saved_;
};

TEST_F(WallClockTime, PlainSecondsAreSessionSecondsAsBefore)
{
    for (const auto& [text, v] : std::vector<std::pair<std::string, double>>{
                 {"0", 0.0}, {"1234.5", 1234.5}, {"60", 60.0}, {"1e9", 1e9}, {"0.25", 0.25}}) {
        const auto a = parse(text);
        EXPECT_EQ(a.form, Form::SessionSeconds) << text;
        EXPECT_EQ(a.seconds, v) << text;
    }
    for (const char* s : {"-1", "1e10", "nan", "inf", "abc", "", "12abc", " 5", "2026-12-06"}) {
        refused(s);
    }
}

TEST_F(WallClockTime, TimesOfDay)
{
    EXPECT_EQ(parse("14:32:05").form, Form::TimeOfDay);
    EXPECT_EQ(parse("14:32:05").nsOfDay, (14 * 3600 + 32 * 60 + 5) * kS);
    EXPECT_EQ(parse("14:32").nsOfDay, (14 * 3600 + 32 * 60) * kS);
    EXPECT_EQ(parse("00:00:00").nsOfDay, 0);
    EXPECT_EQ(parse("23:59:59.999").nsOfDay, 86'399'999'000'000LL);
    EXPECT_EQ(parse("14:32:05.25").nsOfDay, (14 * 3600 + 32 * 60 + 5) * kS + 250'000'000);
    EXPECT_EQ(parse("14:32:05,5").nsOfDay, (14 * 3600 + 32 * 60 + 5) * kS + 500'000'000);
    // Digits past the nanosecond are read and dropped.
    EXPECT_EQ(parse("00:00:00.1234567891").nsOfDay, 123'456'789);
}

TEST_F(WallClockTime, MalformedTimesOfDaySayWhy)
{
    EXPECT_NE(refused("24:00").find("end of a day"), std::string::npos);
    EXPECT_NE(refused("24:00:00").find("00:00:00 of the next day"), std::string::npos);
    EXPECT_NE(refused("23:59:60").find("leap second"), std::string::npos);
    EXPECT_NE(refused("24:30").find("hours run 00-23"), std::string::npos);
    refused("23:60:00");
    refused("23:59:61");
    refused("9:05:00");
    refused("14:32:5");
    refused("14:32:05.");
    refused("14:32:05 ");
    refused("14::05");
    refused(":");
    EXPECT_NE(refused("14:32:05Z").find("needs the date"), std::string::npos);
    EXPECT_NE(refused("garbage:").find("14:32:05"), std::string::npos); // names the forms
}

TEST_F(WallClockTime, IsoInstants)
{
    EXPECT_EQ(parse("2026-12-06T14:32:05Z").form, Form::Instant);
    EXPECT_EQ(parse("2026-12-06T14:32:05Z").unixNs, k143205Z);
    EXPECT_EQ(parse("2026-12-06t14:32:05z").unixNs, k143205Z);
    EXPECT_EQ(parse("2026-12-06T15:32:05+01:00").unixNs, k143205Z);
    EXPECT_EQ(parse("2026-12-06T15:32:05+0100").unixNs, k143205Z);
    EXPECT_EQ(parse("2026-12-06T15:32:05+01").unixNs, k143205Z);
    EXPECT_EQ(parse("2026-12-06T09:02:05-05:30").unixNs, k143205Z);
    EXPECT_EQ(parse("2026-12-06T14:32:05-00:00").unixNs, k143205Z);
    EXPECT_EQ(parse("2026-12-06T14:32:05.123456789Z").unixNs, k143205Z + 123'456'789);
    // Across midnight by the offset: 00:30+01:00 is the day before's 23:30Z.
    EXPECT_EQ(parse("2026-12-07T00:30:00+01:00").unixNs, 1796599800LL * kS);
    // Leap days: 2028 and 2000 have one, 2026 and 2100 not.
    EXPECT_EQ(parse("2028-02-29T12:00:00Z").unixNs, 1835438400LL * kS);
    EXPECT_EQ(parse("2028-03-01T00:00:00Z").unixNs - parse("2028-02-28T00:00:00Z").unixNs,
              2 * 86400 * kS);
    parse("2000-02-29T00:00:00Z");
    EXPECT_NE(refused("2026-02-29T12:00:00Z").find("no day 29"), std::string::npos);
    refused("2100-02-29T12:00:00Z");
    refused("2026-13-01T00:00:00Z");
    refused("2026-00-10T00:00:00Z");
    refused("2026-04-31T00:00:00Z");
    EXPECT_NE(refused("2026-12-06T23:59:60Z").find("leap second"), std::string::npos);
    refused("2026-12-06T24:00:00Z");
    refused("2026-12-06T14:32:05+24:00");
    refused("2026-12-06T14:32:05+01:60");
    refused("2026-12-06T14:32:05+1");
    refused("2026-12-06T14:32:05Zjunk");
    refused("2026-12-06 14:32:05Z");
    refused("2026-12-6T14:32:05Z");
    refused("20261206T143205Z");
    EXPECT_EQ(daysFromCivil(1970, 1, 1), 0);
    EXPECT_EQ(daysFromCivil(1969, 12, 31), -1);
    EXPECT_EQ(daysFromCivil(2000, 3, 1), 11017);
}

TEST_F(WallClockTime, LocalDateTimeHasNoZone)
{
    const auto a = parse("2026-12-06T14:32:05.5");
    EXPECT_EQ(a.form, Form::LocalDateTime);
    EXPECT_EQ(a.year, 2026);
    EXPECT_EQ(a.month, 12);
    EXPECT_EQ(a.day, 6);
    EXPECT_EQ(a.nsOfDay, (14 * 3600 + 32 * 60 + 5) * kS + 500'000'000);
}

TEST_F(WallClockTime, TimeOfDayAgainstTheRecording)
{
    const RecordingSpan span{1796565600LL * kS, 3600 * kS}; // 14:00Z for an hour
    auto r = resolve("14:32:05", span);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->sessionS, 1925.0);
    EXPECT_EQ(r->unixNs, k143205Z);
    r = resolve("14:32:05.5", span);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 1925.5);
    r = resolve("14:00", span);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 0.0);
    r = resolve("15:00:00", span); // the last frame's instant is inside
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 3600.0);
    // Before the start, on a recording that does not span midnight: refused, with the span in
    // both clocks.
    r = resolve("13:59:00", span);
    ASSERT_FALSE(r);
    const auto& m = r.error().message;
    EXPECT_NE(m.find("--from 13:59:00"), std::string::npos) << m;
    EXPECT_NE(m.find("outside the recording"), std::string::npos) << m;
    EXPECT_NE(m.find("session seconds 0 to 3600.000"), std::string::npos) << m;
    EXPECT_NE(m.find("2026-12-06T14:00:00.000+00:00 to 2026-12-06T15:00:00.000+00:00"),
              std::string::npos)
            << m;
    EXPECT_NE(m.find("2026-12-06T14:00:00.000Z to 2026-12-06T15:00:00.000Z"), std::string::npos)
            << m;
    EXPECT_FALSE(resolve("15:00:01", span));
}

TEST_F(WallClockTime, AcrossMidnight)
{
    const RecordingSpan span{1796599800LL * kS, 3600 * kS}; // 23:30Z to 00:30Z
    auto r = resolve("00:15", span);                        // the next day's
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->sessionS, 2700.0);
    r = resolve("23:45", span);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 900.0);
    EXPECT_FALSE(resolve("23:00", span));
    EXPECT_FALSE(resolve("00:45", span));
    // In another zone the same recording is 00:30 to 01:30 on one day: no midnight to span.
    zone("CET-1");
    r = resolve("00:45", span);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 900.0);
    EXPECT_FALSE(resolve("23:45", span));
}

TEST_F(WallClockTime, LongerThanADayIsAmbiguous)
{
    const RecordingSpan span{1796551200LL * kS, 30 * 3600 * kS}; // 10:00Z, 30 h
    auto r = resolve("11:00", span);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("names both 2026-12-06T11:00:00.000+00:00 and "
                                     "2026-12-07T11:00:00.000+00:00"),
              std::string::npos)
            << r.error().message;
    r = resolve("09:00", span); // only the second day's is inside
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 23.0 * 3600);
    r = resolve("2026-12-07T11:00:00Z", span);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 25.0 * 3600);
}

TEST_F(WallClockTime, DaylightSavingTime)
{
    zone("CET-1CEST,M3.5.0,M10.5.0/3");
    // 2026-03-29: 02:00 CET jumps to 03:00 CEST. Recording 00:00Z (01:00 CET) for 3 h.
    const RecordingSpan spring{1774742400LL * kS, 3 * 3600 * kS};
    auto r = resolve("02:30", spring);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("no such time"), std::string::npos) << r.error().message;
    r = resolve("03:30", spring);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 5400.0);
    r = resolve("01:30", spring);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 1800.0);
    // Z and offsets are instants: no DST applies, the gap's UTC time is an ordinary one.
    r = resolve("2026-03-29T01:30:00Z", spring);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 5400.0);
    r = resolve("2026-03-29T02:30:00+01:00", spring);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 5400.0);
    // 2026-10-25: 03:00 CEST falls back to 02:00 CET; 02:30 happens twice. Recording 23:00Z
    // (01:00 CEST) for 4 h.
    const RecordingSpan autumn{1792882800LL * kS, 4 * 3600 * kS};
    r = resolve("02:30", autumn);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("names both 2026-10-25T02:30:00.000+02:00 and "
                                     "2026-10-25T02:30:00.000+01:00"),
              std::string::npos)
            << r.error().message;
    EXPECT_FALSE(resolve("2026-10-25T02:30:00", autumn));
    r = resolve("2026-10-25T02:30:00+01:00", autumn);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 9000.0);
    r = resolve("2026-10-25T01:30:00", autumn); // once only: CEST
    ASSERT_TRUE(r);
    EXPECT_EQ(r->sessionS, 1800.0);
}

TEST_F(WallClockTime, InstantsDoNotDependOnTheZone)
{
    const RecordingSpan span{1796565600LL * kS, 3600 * kS};
    for (const char* tz :
         {"UTC0", "CET-1CEST,M3.5.0,M10.5.0/3", "EST5EDT,M3.2.0,M11.1.0", "<+1345>-13:45"}) {
        zone(tz);
        auto r = resolve("2026-12-06T14:32:05.25Z", span);
        ASSERT_TRUE(r) << tz;
        EXPECT_EQ(r->sessionS, 1925.25) << tz;
        r = resolve("2026-12-06T20:02:05.25+05:30", span);
        ASSERT_TRUE(r) << tz;
        EXPECT_EQ(r->sessionS, 1925.25) << tz;
    }
    zone("CET-1");
    EXPECT_EQ(isoLocal(k143205Z + 250'000'000), "2026-12-06T15:32:05.250+01:00");
    EXPECT_EQ(isoUtcMs(k143205Z + 250'000'000), "2026-12-06T14:32:05.250Z");
    zone("<-0330>3:30");
    EXPECT_EQ(isoLocal(k143205Z), "2026-12-06T11:02:05.000-03:30");
}

TEST_F(WallClockTime, OutsideAndNoStart)
{
    const RecordingSpan span{1796565600LL * kS, 3600 * kS};
    auto r = resolve("2026-12-06T13:59:59.9Z", span);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("outside the recording"), std::string::npos);
    r = resolve("2026-12-07T14:30:00Z", span);
    ASSERT_FALSE(r);
    r = resolve("14:30", RecordingSpan{0, 3600 * kS});
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("no wall-clock start"), std::string::npos);
}

} // namespace
} // namespace replica::platform
