// The display's stand: the screen turns about a horizontal hinge; the tilt angle gives its pose.
#pragma once

#include <optional>

#include <glm/vec3.hpp>

namespace replica::pipeline::scene {

struct StandModel {
    glm::dvec3 hingeM{0.0, 0.15, -0.10}; // a point on the hinge axis (the axis is booth x)
    double hingeToPanelM = 0.03; // from the hinge to the panel's bottom edge, along the panel
    double panelWidthM = 0.518;  // active area of a 24-inch 16:10 panel
    double panelHeightM = 0.324;
};

// The panel in the booth frame: its bottom-left corner of the active area and full edge vectors.
struct PanelPose {
    glm::dvec3 originM{0.0}; // bottom-left corner of the active area
    glm::dvec3 rightM{0.0};  // full width along the panel's x
    glm::dvec3 upM{0.0};     // full height along the panel's y
    glm::dvec3 normal{0.0};  // out of the screen, towards the viewer
};

// tiltRad = 0 is vertical; positive leans the top back so the screen faces up towards the ceiling.
PanelPose panelPose(const StandModel& stand, double tiltRad);

// The tilt from gravity measured in the panel frame (x right, y up the panel, z out of the screen),
// or nullopt when it is undefined: gravity (nearly) along the hinge axis, implausible magnitude, or
// NaN.
std::optional<double> tiltFromGravity(const glm::dvec3& gravityPanel);

} // namespace replica::pipeline::scene
