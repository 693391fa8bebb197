// A rigid transform between two right-handed frames in metres (rotation + translation), and the
// one the appliance needs: T_booth_tracker, the tracker's pose in the booth frame. Header-only
// vocabulary, so that hal's simulated tracker and the state stage share it.
#pragma once

#include <cmath>
#include <numbers>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>

namespace replica::pipeline {

// p_to = rotation * p_from + translation (rotation orthonormal, determinant +1).
struct RigidTransform {
    glm::dmat3 rotation{1.0};
    glm::dvec3 translation{0.0};

    // The one function that carries a point across (e.g. the tracked eye into the booth frame).
    glm::dvec3 apply(const glm::dvec3& p) const { return rotation * p + translation; }
    // p_from from p_to: rotation^T (p - translation).
    glm::dvec3 applyInverse(const glm::dvec3& p) const
    {
        return glm::transpose(rotation) * (p - translation);
    }
    RigidTransform inverse() const
    {
        const glm::dmat3 rt = glm::transpose(rotation);
        return {rt, -(rt * translation)};
    }
    friend bool operator==(const RigidTransform&, const RigidTransform&) = default;
};

// The rotation about x, then y, then z by anglesRad: Rz * Ry * Rx. Zero angles give the identity
// exactly.
inline glm::dmat3 rotationXyz(const glm::dvec3& anglesRad)
{
    if (anglesRad == glm::dvec3(0.0)) {
        return glm::dmat3(1.0);
    }
    const glm::dvec3& r = anglesRad;
    // glm is column-major: each group of three is a column.
    const auto rx =
            glm::dmat3(1, 0, 0, 0, std::cos(r.x), std::sin(r.x), 0, -std::sin(r.x), std::cos(r.x));
    const auto ry =
            glm::dmat3(std::cos(r.y), 0, -std::sin(r.y), 0, 1, 0, std::sin(r.y), 0, std::cos(r.y));
    const auto rz =
            glm::dmat3(std::cos(r.z), std::sin(r.z), 0, -std::sin(r.z), std::cos(r.z), 0, 0, 0, 1);
    return rz * ry * rx;
}

// The I/O edge's form (site file [tracker] rotation_deg / translation_m, recordings made before the
// matrix was recorded): angles in degrees about x, then y, then z, and a translation.
inline RigidTransform rigidFromDegrees(const glm::dvec3& rotationDeg, const glm::dvec3& translation)
{
    return {rotationXyz(rotationDeg * (std::numbers::pi / 180.0)), translation};
}

// Whether m is a rotation up to 'tolerance' in each entry of m^T m - I and in det(m) - 1, and
// finite.
inline bool isRotation(const glm::dmat3& m, double tolerance = 1e-6)
{
    const glm::dmat3 e = glm::transpose(m) * m;
    for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) {
            if (!std::isfinite(m[c][r]) ||
                !(std::abs(e[c][r] - (c == r ? 1.0 : 0.0)) <= tolerance)) {
                return false;
            }
        }
    }
    return std::abs(glm::determinant(m) - 1.0) <= tolerance;
}

// T_booth_tracker of the fixed mounting (the site file's default and what recordings made without
// one replay with): the tracker unrotated, its origin on the stand's base 0.42 m up and 0.05 m
// towards the viewer from the booth's floor centre.
inline constexpr glm::dvec3 kDefaultTrackerInBoothM{0.0, 0.42, 0.05};
inline RigidTransform defaultTrackerInBooth()
{
    return {glm::dmat3(1.0), kDefaultTrackerInBoothM};
}

} // namespace replica::pipeline
