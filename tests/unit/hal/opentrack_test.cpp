// The opentrack head-pose receiver over a real loopback UDP socket: decoding, geometry, the
// receiver policy for bad datagrams, and staleness.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <hal/log_limiter.h>
#include <hal/tracker/opentrack_source.h>

#include <gtest/gtest.h>

#include "../support/eventually.h"

namespace replica::tests {
namespace {

using namespace hal::tracker;

std::vector<std::uint8_t> datagram(std::array<double, 6> v)
{
    std::vector<std::uint8_t> b(48);
    std::memcpy(b.data(), v.data(), 48);
    return b;
}

TEST(Opentrack, DecodesSixDoublesAndRejectsBadDatagrams)
{
    auto p = decodeOpentrack(datagram({1.5, -2.0, 60.0, 10.0, -5.0, 2.5}));
    ASSERT_TRUE(p);
    EXPECT_DOUBLE_EQ(p->positionCm.x, 1.5);
    EXPECT_DOUBLE_EQ(p->positionCm.z, 60.0);
    EXPECT_DOUBLE_EQ(p->yawDeg, 10.0);
    EXPECT_DOUBLE_EQ(p->rollDeg, 2.5);
    auto shortOne = datagram({0, 0, 0, 0, 0, 0});
    shortOne.pop_back();
    EXPECT_FALSE(decodeOpentrack(shortOne));
    EXPECT_FALSE(
            decodeOpentrack(datagram({0, std::numeric_limits<double>::quiet_NaN(), 0, 0, 0, 0})));
    EXPECT_FALSE(
            decodeOpentrack(datagram({0, 0, 0, 0, std::numeric_limits<double>::infinity(), 0})));
}

TEST(Opentrack, EyeOffsetTurnsWithTheHead)
{
    HeadPose p;
    p.positionCm = {10.0, 20.0, 50.0};
    TrackerMounting m;
    m.eyeOffsetHeadM = {0.0, 0.0, 0.0};
    const glm::dvec3 e0 = eyeFromHeadPose(p, m);
    EXPECT_DOUBLE_EQ(e0.x, 0.10);
    EXPECT_DOUBLE_EQ(e0.y, 0.20);
    EXPECT_DOUBLE_EQ(e0.z, -0.50); // opentrack's forward is away from the viewer
    // An offset along +x, yawed by 90 degrees, ends up along -z (right-handed rotation about y).
    m.eyeOffsetHeadM = {0.05, 0.0, 0.0};
    p.yawDeg = 90.0;
    const glm::dvec3 e = eyeFromHeadPose(p, m);
    EXPECT_NEAR(e.x, 0.10, 1e-12);
    EXPECT_NEAR(e.z, -0.50 - 0.05, 1e-12);
    // Rotations keep the offset's length.
    p.pitchDeg = 33.0;
    p.rollDeg = -71.0;
    const glm::dvec3 d = eyeFromHeadPose(p, m) - e0;
    EXPECT_NEAR(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), 0.05, 1e-12);
}

void sendTo(std::uint16_t port, const std::vector<std::uint8_t>& bytes)
{
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
    ASSERT_EQ(::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&addr),
                       sizeof addr),
              static_cast<ssize_t>(bytes.size()));
    ::close(fd);
}

TEST(OpentrackSource, ReceivesPosesDropsBadOnesAndGoesStale)
{
    hal::SteadyClock clock;
    OpentrackSourceOptions opt;
    opt.port = 0;
    // Long enough that a loaded machine cannot make the fresh poses stale before they are polled.
    opt.staleNs = 1'000'000'000;
    // Every datagram its own pose: the four below arrive within microseconds, which the default
    // coalesces (FloodIsCoalescedLoggedAtABoundedRateAndTheLatestPoseWins).
    opt.minIntervalNs = 0;
    auto src = makeOpentrackSource(clock, opt);
    ASSERT_TRUE(src) << src.error().message;
    const std::uint16_t port = (*src)->boundPort();
    ASSERT_NE(port, 0);
    EXPECT_EQ((*src)->state(), hal::LinkState::Lost);

    sendTo(port, datagram({1.0, 2.0, 60.0, 0, 0, 0}));
    sendTo(port, {1, 2, 3});
    sendTo(port, datagram({0, std::numeric_limits<double>::quiet_NaN(), 0, 0, 0, 0}));
    sendTo(port, datagram({3.0, 4.0, 70.0, 0, 0, 0}));
    std::vector<hal::PoseSample> got;
    ASSERT_TRUE(eventually([&] {
        (*src)->poll(clock.nowNs(), got);
        return got.size() >= 2;
    }));
    EXPECT_EQ((*src)->rejectedDatagrams(), 2);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_TRUE(got[0].tracked);
    EXPECT_DOUBLE_EQ(got[0].eyeTrackerM.x, 0.01);
    EXPECT_DOUBLE_EQ(got[1].eyeTrackerM.z, -0.70);
    EXPECT_EQ(got[1].sequence, got[0].sequence + 1);
    EXPECT_EQ((*src)->state(), hal::LinkState::Connected);
    // Raw in, processed out: each pose carries the datagram as it arrived and the mounting.
    ASSERT_TRUE(got[1].raw);
    EXPECT_EQ(got[1].raw->kind, hal::RawTrackerInput::Kind::OpentrackDatagram);
    EXPECT_EQ(got[1].raw->bytes, datagram({3.0, 4.0, 70.0, 0, 0, 0}));
    EXPECT_EQ(got[1].raw->arrivalNs, got[1].timestampNs);
    EXPECT_EQ(got[1].raw->zSign, -1.0);

    // Silence: the source turns Stalled and reports one untracked sample.
    ASSERT_TRUE(eventually([&] { return (*src)->state() == hal::LinkState::Stalled; }));
    got.clear();
    (*src)->poll(clock.nowNs(), got);
    ASSERT_EQ(got.size(), 1u);
    EXPECT_FALSE(got[0].tracked);
    EXPECT_FALSE(got[0].raw); // made by the source, not by the device
    got.clear();
    (*src)->poll(clock.nowNs(), got);
    EXPECT_TRUE(got.empty());
}

// A sender flooding the port (a second opentrack, a misconfigured rate, an attacker on the LAN):
// the receiver keeps at most one pose per 2 ms, the latest, counts the rest, and logs one line per
// kind of excess per 10 s, not one per datagram or per frame. Before, every good datagram was a
// pose (1024 a frame reached the loop and the recording) and the loop logged its drops each frame.
TEST(OpentrackSource, FloodIsCoalescedLoggedAtABoundedRateAndTheLatestPoseWins)
{
    std::ostringstream captured;
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
    spdlog::drop("hal.tracker");
    spdlog::register_logger(std::make_shared<spdlog::logger>("hal.tracker", sink));
    hal::SteadyClock clock;
    OpentrackSourceOptions opt;
    opt.port = 0;
    opt.staleNs = 5'000'000'000;
    auto src = makeOpentrackSource(clock, opt);
    ASSERT_TRUE(src) << src.error().message;
    const std::uint16_t port = (*src)->boundPort();

    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
    auto send = [&](const std::vector<std::uint8_t>& bytes) {
        ::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<sockaddr*>(&addr),
                 sizeof addr);
    };
    constexpr int kFlood = 20000;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<hal::PoseSample> got;
    for (int i = 0; i < kFlood; ++i) {
        if (i % 10 == 9) {
            send(datagram({0, std::numeric_limits<double>::quiet_NaN(), 0, 0, 0, 0}));
        } else {
            send(datagram({static_cast<double>(i % 100), 0, 60.0, 0, 0, 0}));
        }
        if (i % 1000 == 0) {
            (*src)->poll(clock.nowNs(), got); // the loop polls now and then meanwhile
        }
    }
    // The last pose, sent once the flood has been read: it must be the one the loop ends up with.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    send(datagram({123.0, 0, 60.0, 0, 0, 0}));
    ASSERT_TRUE(eventually([&] {
        (*src)->poll(clock.nowNs(), got);
        return !got.empty() && got.back().tracked &&
               std::abs(got.back().eyeTrackerM.x - 1.23) < 1e-12;
    }));
    const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ::close(fd);
    // At most one pose per 2 ms reached the loop (plus the stale report, if any), far fewer than
    // were sent; every NaN datagram that was read is counted as rejected.
    EXPECT_LE(static_cast<double>(got.size()), seconds / 0.002 + 2) << seconds << " s";
    EXPECT_LT(got.size(), static_cast<std::size_t>(kFlood / 10));
    EXPECT_GT((*src)->coalescedDatagrams(), 0);
    EXPECT_GT((*src)->rejectedDatagrams(), 0);
    for (std::size_t i = 1; i < got.size(); ++i) {
        EXPECT_EQ(got[i].sequence, got[i - 1].sequence + 1) << "a pose lost after coalescing";
    }
    src->reset();
    spdlog::drop("hal.tracker");
    const std::string text = captured.str();
    // One line for the first rejected datagram, one for the first coalesced pose; the rest of
    // the flood falls within their 10 s.
    EXPECT_LE(std::count(text.begin(), text.end(), '\n'), 2) << text;
    EXPECT_NE(text.find("skipped for a later one"), std::string::npos) << text;
    EXPECT_NE(text.find("on port " + std::to_string(port) + " (the last 48 bytes; opentrack"),
              std::string::npos)
            << text;
}

// The limiter behind those lines: the first event at once, then one line per interval with the
// count since the last one, and nothing lost at the end of a burst.
TEST(LogLimiter, FirstAtOnceThenOneLinePerIntervalWithTheCount)
{
    hal::LogLimiter limiter(1000);
    EXPECT_EQ(limiter.add(1, 0), 1u);
    std::uint64_t reported = 1;
    int lines = 1;
    for (std::int64_t t = 1; t < 5000; ++t) { // an event every tick for 5 intervals
        if (const auto n = limiter.add(1, t); n > 0) {
            reported += n;
            ++lines;
        }
    }
    EXPECT_EQ(lines, 5);
    EXPECT_EQ(limiter.flush(4500), 0u); // not yet an interval since the last line (at 4000)
    reported += limiter.flush(5000);
    EXPECT_EQ(reported, 5000u);
    EXPECT_EQ(limiter.total(), 5000u);
    EXPECT_EQ(limiter.flush(9000), 0u); // nothing pending
}

TEST(OpentrackSource, APortInUseIsAClearError)
{
    hal::SteadyClock clock;
    OpentrackSourceOptions opt;
    opt.port = 0;
    auto first = makeOpentrackSource(clock, opt);
    ASSERT_TRUE(first);
    opt.port = (*first)->boundPort();
    auto second = makeOpentrackSource(clock, opt);
    ASSERT_FALSE(second);
    EXPECT_NE(second.error().message.find(std::to_string(opt.port)), std::string::npos);
    opt.bindAddress = "not-an-address";
    auto third = makeOpentrackSource(clock, opt);
    ASSERT_FALSE(third);
    EXPECT_NE(third.error().message.find("IPv4"), std::string::npos);
}

} // namespace
} // namespace replica::tests
