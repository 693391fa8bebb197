// The display's stand: the screen turns about a horizontal hinge; the tilt angle gives its pose.
#pragma once

#include <numbers>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

namespace replica::pipeline::scene {

struct StandModel {
    glm::dvec3 hingeM{0.0, 0.15, -0.10}; // a point on the hinge axis (the axis is booth x)
    double hingeToPanelM = 0.03; // from the hinge to the panel's bottom edge, along the panel
    double panelWidthM = 0.518;  // active area of a 24-inch 16:10 panel
    double panelHeightM = 0.324;
};

// The panel's active area in the booth frame (the one panel pose: the CPU model's View, the booth
// pass and pass 2 all take it): its centre, unit axes and size.
struct PanelPose {
    glm::dvec3 centre{0.0};           // centre of the active area
    glm::dvec3 right{1.0, 0.0, 0.0};  // unit, along the panel's x
    glm::dvec3 up{0.0, 1.0, 0.0};     // unit, up the panel's y
    glm::dvec3 normal{0.0, 0.0, 1.0}; // cross(right, up): out of the screen, towards the viewer
    double widthM = StandModel{}.panelWidthM;
    double heightM = StandModel{}.panelHeightM;

    glm::dvec3 rightEdgeM() const { return right * widthM; } // the full width along right
    glm::dvec3 upEdgeM() const { return up * heightM; }      // the full height along up
    glm::dvec3 cornerM() const { return centre - 0.5 * rightEdgeM() - 0.5 * upEdgeM(); }
};

// tiltRad = 0 is vertical; positive leans the top back so the screen faces up towards the ceiling.
// Radians, as everywhere inside; degrees only at the edges (the CLI, the site file), converted
// there with degreesToRadians.
PanelPose panelPose(const StandModel& stand, double tiltRad);
PanelPose panelPose(double tiltRad); // the default stand

constexpr double degreesToRadians(double deg)
{
    return deg * std::numbers::pi / 180.0;
}

// The tilt from gravity measured in the panel frame (x right, y up the panel, z out of the screen),
// or nullopt when it is undefined: gravity (nearly) along the hinge axis, implausible magnitude, or
// NaN.
std::optional<double> tiltFromGravity(const glm::dvec3& gravityPanel);
// Why tiltFromGravity gives none for this reading ("" when it gives a tilt): for the log line that
// says what the frame held on to.
std::string whyNoTilt(const glm::dvec3& gravityPanel);

} // namespace replica::pipeline::scene
