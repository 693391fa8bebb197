// opentrack datagram decoding and head-to-eye geometry.
#include <cmath>
#include <cstring>

#include <hal/tracker/opentrack_udp.h>

namespace replica::hal::tracker {

std::optional<HeadPose> decodeOpentrack(std::span<const std::uint8_t> datagram)
{
    if (datagram.size() != kOpentrackDatagramBytes) {
        return std::nullopt;
    }
    // Native byte order by the protocol's definition; every supported target is little-endian.
    std::array<double, 6> v{};
    std::memcpy(v.data(), datagram.data(), kOpentrackDatagramBytes);
    for (const double x : v) {
        if (!std::isfinite(x)) {
            return std::nullopt;
        }
    }
    HeadPose p;
    p.positionCm = {v[0], v[1], v[2]};
    p.yawDeg = v[3];
    p.pitchDeg = v[4];
    p.rollDeg = v[5];
    return p;
}

glm::dvec3 eyeFromHeadPose(const HeadPose& pose, const TrackerMounting& mounting)
{
    constexpr double kDeg = 3.14159265358979323846 / 180.0;
    const glm::dvec3 posM{pose.positionCm.x * 0.01, pose.positionCm.y * 0.01,
                          mounting.zSign * pose.positionCm.z * 0.01};
    const glm::dvec3 o = mounting.eyeOffsetHeadM;
    if (o == glm::dvec3(0.0)) {
        return posM;
    }
    // Head rotation R = yaw (about y) * pitch (about x) * roll (about z), in the tracker frame.
    const double cy = std::cos(pose.yawDeg * kDeg), sy = std::sin(pose.yawDeg * kDeg);
    const double cp = std::cos(pose.pitchDeg * kDeg), sp = std::sin(pose.pitchDeg * kDeg);
    const double cr = std::cos(pose.rollDeg * kDeg), sr = std::sin(pose.rollDeg * kDeg);
    const glm::dvec3 r1{cr * o.x - sr * o.y, sr * o.x + cr * o.y, o.z};       // roll
    const glm::dvec3 r2{r1.x, cp * r1.y - sp * r1.z, sp * r1.y + cp * r1.z};  // pitch
    const glm::dvec3 r3{cy * r2.x + sy * r2.z, r2.y, -sy * r2.x + cy * r2.z}; // yaw
    return posM + r3;
}

} // namespace replica::hal::tracker
