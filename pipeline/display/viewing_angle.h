// How the panel's output changes with viewing angle, from a measurement table, and the per-pixel
// compensation that follows from it: each pixel has its own angle to the tracked eye.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>

namespace replica::pipeline::display {

// Measured white at angles off the panel normal: luminance relative to on-axis, and the shift of
// its chromaticity (x, y) from on-axis. Rows strictly increasing in angle, the first at 0 deg.
struct ViewingAngleTable {
    std::vector<double> angleDeg;
    std::vector<double> luminanceRatio; // 1 at 0 deg
    std::vector<double> dx;             // chromaticity shift of white, 0 at 0 deg
    std::vector<double> dy;

    bool empty() const { return angleDeg.empty(); }
    // Fails naming the row when the table is not usable (unsorted, ratio <= 0, first row not 0).
    Expected<void> validate() const;
};

// The per-component XYZ gain from on-axis to this angle: what the eye receives is
// gain * (what a meter on the normal would read), the white's change applied as a diagonal in XYZ.
// Gains are linear in angle between rows; beyond the last row the last row holds. An empty table
// gives (1, 1, 1). whiteXyz is the panel's on-axis white.
glm::dvec3 viewingGain(const ViewingAngleTable& table, const glm::dvec3& whiteXyz, double angleDeg);

// Angle between the panel normal and the direction from the pixel to the eye, in degrees. An eye in
// or behind the panel plane gives 90 (the table's last row then applies); a zero-length direction
// gives 0.
// The gain at one table row (what the shader's table holds).
glm::dvec3
viewingGainAtRow(const ViewingAngleTable& table, const glm::dvec3& whiteXyz, std::size_t row);

double
viewingAngleDeg(const glm::dvec3& pixelM, const glm::dvec3& panelNormal, const glm::dvec3& eyeM);

} // namespace replica::pipeline::display
