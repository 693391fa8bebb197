// Forward display model.
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <glm/matrix.hpp>

#include <pipeline/display/display_model.h>

namespace replica::pipeline::display {

double DisplayModel::maxCount() const
{
    return std::ldexp(1.0, bitDepth) - 1.0;
}

glm::dvec3 DisplayModel::linearFromCounts(const glm::dvec3& counts) const
{
    return {tone[0](counts.x), tone[1](counts.y), tone[2](counts.z)};
}

glm::dvec3 DisplayModel::forward(const glm::dvec3& counts) const
{
    return blackXyz + matrix * linearFromCounts(counts);
}

Expected<void> DisplayModel::validate() const
{
    if (bitDepth < 1 || bitDepth > 16) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("display profile '{}': bit depth {} is outside 1..16", name, bitDepth));
    }
    constexpr std::array<char, 3> kNames{'R', 'G', 'B'};
    for (std::size_t c = 0; c < 3; ++c) {
        const auto& t = tone[c];
        if (t.empty() || t.counts().front() != 0.0 || t.counts().back() != maxCount() ||
            std::abs(t.values().front()) > 1e-9 || std::abs(t.values().back() - 1.0) > 1e-9) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("display profile '{}': channel {} tone curve must run "
                                         "from count 0 (r = 0) to count {} (r = 1)",
                                         name, kNames[c], maxCount()));
        }
    }
    const double det = glm::determinant(matrix);
    if (!std::isfinite(det) || std::abs(det) < 1e-12) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("display profile '{}': the primaries matrix is singular", name));
    }
    for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(blackXyz[i]) || blackXyz[i] < 0.0) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("display profile '{}': black XYZ must be finite and "
                                         ">= 0",
                                         name));
        }
    }
    if (!(frontSurfaceReflectance >= 0.0 && frontSurfaceReflectance < 0.2)) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("display profile '{}': front-surface reflectance {} is "
                                     "outside [0, 0.2)",
                                     name, frontSurfaceReflectance));
    }
    return viewing.validate();
}

glm::dvec3 frontSurfaceFlareXyz(const DisplayModel& model,
                                double illuminanceLux,
                                const glm::dvec3& lightXyzUnitY)
{
    if (model.condition == MeasurementCondition::LitBooth || !(illuminanceLux > 0.0)) {
        return glm::dvec3(0.0);
    }
    return model.frontSurfaceReflectance * illuminanceLux / std::numbers::pi * lightXyzUnitY;
}

} // namespace replica::pipeline::display
