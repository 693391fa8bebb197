// Stand hinge model and tilt from the accelerometer.
#include <cmath>

#include <glm/geometric.hpp>

#include <pipeline/scene/stand.h>

namespace replica::pipeline::scene {

PanelPose panelPose(const StandModel& stand, double tiltRad)
{
    const double c = std::cos(tiltRad);
    const double s = std::sin(tiltRad);
    PanelPose p;
    const glm::dvec3 up{0.0, c, -s};
    p.normal = glm::dvec3{0.0, s, c};
    p.rightM = glm::dvec3{stand.panelWidthM, 0.0, 0.0};
    p.upM = up * stand.panelHeightM;
    p.originM = stand.hingeM + up * stand.hingeToPanelM - 0.5 * p.rightM;
    return p;
}

std::optional<double> tiltFromGravity(const glm::dvec3& g)
{
    if (!std::isfinite(g.x) || !std::isfinite(g.y) || !std::isfinite(g.z)) {
        return std::nullopt;
    }
    constexpr double kStandardGravity = 9.80665;
    const double magnitude = glm::length(g);
    // Gate implausible readings (knocks, free fall): |g| must be within 10 % of 1 g.
    if (std::abs(magnitude - kStandardGravity) > 0.1 * kStandardGravity) {
        return std::nullopt;
    }
    // With gravity nearly along the hinge (x) axis the rotation about x is undefined.
    const double inPlane = std::hypot(g.y, g.z);
    if (inPlane < 0.2 * kStandardGravity) {
        return std::nullopt;
    }
    return std::atan2(-g.z, -g.y);
}

} // namespace replica::pipeline::scene
