// The opentrack UDP protocol: one 48-byte datagram per head pose, six doubles in the sender's
// byte order (x, y, z in cm; yaw, pitch, roll in degrees). Decoding and the eye-position
// geometry, no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include <glm/vec3.hpp>

namespace replica::hal::tracker {

constexpr std::size_t kOpentrackDatagramBytes = 48;
constexpr std::uint16_t kOpentrackDefaultPort = 4242;

struct HeadPose {
    glm::dvec3 positionCm{0.0}; // +x right, +y up, +z forward (opentrack's documented convention)
    double yawDeg = 0.0;        // right positive
    double pitchDeg = 0.0;      // up positive
    double rollDeg = 0.0;       // right positive
};

// nullopt for a datagram of the wrong length or with a NaN/Inf component: opentrack's own
// receiver drops those without touching the last good pose, and so do we.
std::optional<HeadPose> decodeOpentrack(std::span<const std::uint8_t> datagram);

// Where the tracker sits and how its axes map to the tracker frame of PoseSample (x right, y up,
// z towards the viewer, metres), and where the eyes are relative to the tracked head point.
struct TrackerMounting {
    double zSign = -1.0;            // opentrack's +z is forward, away from the viewer
    glm::dvec3 eyeOffsetHeadM{0.0}; // head frame: from the tracked point to the eyes' midpoint
};

// Eye midpoint in the tracker frame, metres: position plus the head-rotated eye offset.
glm::dvec3 eyeFromHeadPose(const HeadPose& pose, const TrackerMounting& mounting);

} // namespace replica::hal::tracker
