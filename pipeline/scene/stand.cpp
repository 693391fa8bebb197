// Stand hinge model and tilt from the accelerometer.
#include <cmath>

#include <fmt/format.h>
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

namespace {

constexpr double kStandardGravity = 9.80665;

} // namespace

std::string whyNoTilt(const glm::dvec3& g)
{
    if (!std::isfinite(g.x) || !std::isfinite(g.y) || !std::isfinite(g.z)) {
        return "a reading that is not finite";
    }
    const double magnitude = glm::length(g);
    // Gate implausible readings (knocks, free fall): |g| must be within 10 % of 1 g.
    if (std::abs(magnitude - kStandardGravity) > 0.1 * kStandardGravity) {
        return fmt::format("|g| {:.3f} m/s^2 ({:.2f} g), outside 0.9-1.1 g: a knock, the panel "
                           "moved, or the sensor's scale is off",
                           magnitude, magnitude / kStandardGravity);
    }
    // With gravity nearly along the hinge (x) axis the rotation about x is undefined.
    const double inPlane = std::hypot(g.y, g.z);
    if (inPlane < 0.2 * kStandardGravity) {
        return fmt::format("gravity along the hinge ({:.2f} g of it across the hinge, under "
                           "0.2 g): check the accelerometer's axes",
                           inPlane / kStandardGravity);
    }
    return "";
}

std::optional<double> tiltFromGravity(const glm::dvec3& g)
{
    if (!whyNoTilt(g).empty()) {
        return std::nullopt;
    }
    return std::atan2(-g.z, -g.y);
}

} // namespace replica::pipeline::scene
