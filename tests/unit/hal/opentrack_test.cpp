// The opentrack head-pose receiver over a real loopback UDP socket: decoding, geometry, the
// receiver policy for bad datagrams, and staleness.
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

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
