// The journal's side of the logs: which stderr is the journal's stream, and the priority each
// level is filed under (syslog's numbers from <syslog.h>, the prefixes from <systemd/sd-daemon.h>'s
// definitions as sd-daemon(3) gives them).
#include <cstdio>
#include <string>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <syslog.h>
#include <unistd.h>

#include <platform/logging.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

TEST(JournalStream, MatchesOnlyTheFileOpenOnTheDescriptor)
{
    char path[] = "/tmp/replica-journal-XXXXXX";
    const int fd = mkstemp(path);
    ASSERT_GE(fd, 0);
    struct stat st {
    };
    ASSERT_EQ(fstat(fd, &st), 0);
    const auto value = fmt::format("{}:{}", static_cast<unsigned long long>(st.st_dev),
                                   static_cast<unsigned long long>(st.st_ino));
    EXPECT_TRUE(journalStreamIs(value.c_str(), fd));
    // Another inode on the same device, the variable unset or empty, and malformed values.
    const auto other = fmt::format("{}:{}", static_cast<unsigned long long>(st.st_dev),
                                   static_cast<unsigned long long>(st.st_ino) + 1);
    EXPECT_FALSE(journalStreamIs(other.c_str(), fd));
    EXPECT_FALSE(journalStreamIs(nullptr, fd));
    EXPECT_FALSE(journalStreamIs("", fd));
    EXPECT_FALSE(journalStreamIs((value + "x").c_str(), fd));
    EXPECT_FALSE(journalStreamIs(std::to_string(st.st_ino).c_str(), fd));
    // A closed descriptor is no stream.
    close(fd);
    unlink(path);
    EXPECT_FALSE(journalStreamIs(value.c_str(), fd));
}

TEST(JournalStream, LevelsFileUnderSyslogPriorities)
{
    EXPECT_EQ(journalPriority(spdlog::level::critical), LOG_CRIT);
    EXPECT_EQ(journalPriority(spdlog::level::err), LOG_ERR);
    EXPECT_EQ(journalPriority(spdlog::level::warn), LOG_WARNING);
    EXPECT_EQ(journalPriority(spdlog::level::info), LOG_INFO);
    EXPECT_EQ(journalPriority(spdlog::level::debug), LOG_DEBUG);
    EXPECT_EQ(journalPriority(spdlog::level::trace), LOG_DEBUG);
}

TEST(JournalStream, StreamLinesCarryTheSdDaemonPrefix)
{
    // SD_WARNING and SD_ERR of sd-daemon(3): "<4>" and "<3>".
    EXPECT_EQ(journalStreamLine(spdlog::level::warn, "booth", "lamp drift"),
              "<4>[booth] lamp drift\n");
    EXPECT_EQ(journalStreamLine(spdlog::level::err, "hal.tracker", "gone"),
              "<3>[hal.tracker] gone\n");
}

} // namespace
} // namespace replica::platform
