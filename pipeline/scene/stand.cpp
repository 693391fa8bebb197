// Stand hinge model and tilt from the accelerometer.
#include <cmath>

#include <glm/geometric.hpp>

#include <pipeline/scene/stand.h>

namespace replica::pipeline::scene {

PanelPose panelPose(const StandModel& stand, double tiltRad)
{
    const double c = std::cos(tiltRad);
    const double s = std::sin(tiltRad);
    const glm::dvec3 up{0.0, c, -s};
    const glm::dvec3 rightM{stand.panelWidthM, 0.0, 0.0};
    const glm::dvec3 upM = up * stand.panelHeightM;
    const glm::dvec3 originM = stand.hingeM + up * stand.hingeToPanelM - 0.5 * rightM;
    PanelPose p;
    p.right = glm::normalize(rightM);
    p.up = glm::normalize(upM);
    p.normal = glm::cross(p.right, p.up);
    p.centre = originM + 0.5 * rightM + 0.5 * upM;
    p.widthM = stand.panelWidthM;
    p.heightM = stand.panelHeightM;
    return p;
}

PanelPose panelPose(double tiltRad)
{
    return panelPose(StandModel{}, tiltRad);
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
