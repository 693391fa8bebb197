// Viewing-angle table and gains.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <pipeline/display/viewing_angle.h>

namespace replica::pipeline::display {

Expected<void> ViewingAngleTable::validate() const
{
    const std::size_t n = angleDeg.size();
    if (luminanceRatio.size() != n || dx.size() != n || dy.size() != n) {
        return makeError(ErrorCode::Corrupt,
                         "viewing-angle table: angle, luminance and chromaticity columns differ "
                         "in length");
    }
    if (n == 0) {
        return {};
    }
    if (angleDeg[0] != 0.0) {
        return makeError(ErrorCode::Corrupt, "viewing-angle table: the first row must be 0 deg");
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(angleDeg[i]) || !std::isfinite(luminanceRatio[i]) ||
            !std::isfinite(dx[i]) || !std::isfinite(dy[i]) || !(luminanceRatio[i] > 0.0) ||
            angleDeg[i] > 90.0 || std::abs(dx[i]) > 0.1 || std::abs(dy[i]) > 0.1) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("viewing-angle table row {}: angle in [0, 90], ratio > 0 "
                                         "and |dx|, |dy| <= 0.1 are required",
                                         i + 1));
        }
        if (i > 0 && !(angleDeg[i] > angleDeg[i - 1])) {
            return makeError(
                    ErrorCode::Corrupt,
                    fmt::format("viewing-angle table row {}: angles must increase", i + 1));
        }
    }
    return {};
}

glm::dvec3
viewingGainAtRow(const ViewingAngleTable& table, const glm::dvec3& whiteXyz, std::size_t row)
{
    if (row >= table.angleDeg.size() || !(whiteXyz.y > 0.0)) {
        return {1.0, 1.0, 1.0};
    }
    const double sum = whiteXyz.x + whiteXyz.y + whiteXyz.z;
    const double x0 = whiteXyz.x / sum;
    const double y0 = whiteXyz.y / sum;
    const double x = x0 + table.dx[row];
    const double y = std::max(y0 + table.dy[row], 1e-6);
    // White at the angle, with on-axis Y = 1: (x/y Y, Y, (1-x-y)/y Y) scaled by the ratio.
    const glm::dvec3 onAxis{x0 / y0, 1.0, (1.0 - x0 - y0) / y0};
    const glm::dvec3 atAngle =
            table.luminanceRatio[row] * glm::dvec3{x / y, 1.0, (1.0 - x - y) / y};
    return atAngle / onAxis;
}

glm::dvec3 viewingGain(const ViewingAngleTable& table, const glm::dvec3& whiteXyz, double angleDeg)
{
    if (table.empty() || !(whiteXyz.y > 0.0)) {
        return {1.0, 1.0, 1.0};
    }
    const double a = std::clamp(std::isfinite(angleDeg) ? angleDeg : 90.0, 0.0, 90.0);
    const auto& t = table.angleDeg;
    if (a >= t.back()) {
        return viewingGainAtRow(table, whiteXyz, t.size() - 1);
    }
    // Gains (not ratio and chromaticity) are interpolated, as the shader does.
    const auto it = std::upper_bound(t.begin(), t.end(), a);
    const std::size_t i = static_cast<std::size_t>(it - t.begin()) - 1;
    const double f = (a - t[i]) / (t[i + 1] - t[i]);
    const glm::dvec3 g0 = viewingGainAtRow(table, whiteXyz, i);
    const glm::dvec3 g1 = viewingGainAtRow(table, whiteXyz, i + 1);
    return g0 + f * (g1 - g0);
}

double
viewingAngleDeg(const glm::dvec3& pixelM, const glm::dvec3& panelNormal, const glm::dvec3& eyeM)
{
    const glm::dvec3 d = eyeM - pixelM;
    const double len = glm::length(d);
    const double nLen = glm::length(panelNormal);
    if (!(len > 1e-12) || !(nLen > 1e-12)) {
        return 0.0;
    }
    const double c = glm::dot(d, panelNormal) / (len * nLen);
    if (!(c > 0.0)) {
        return 90.0;
    }
    return std::acos(std::min(c, 1.0)) * 180.0 / std::numbers::pi;
}

} // namespace replica::pipeline::display
