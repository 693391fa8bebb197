// Forward display model.
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <glm/common.hpp>
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

glm::dvec3 crosstalkProducts(const glm::dvec3& r)
{
    return {r.x * r.y, r.y * r.z, r.z * r.x};
}

glm::dvec3 DisplayModel::interacted(const glm::dvec3& r) const
{
    return hasCrosstalk() ? r + crosstalk * crosstalkProducts(r) : r;
}

glm::dvec3 DisplayModel::deinteracted(const glm::dvec3& y, bool clamp) const
{
    if (!hasCrosstalk()) {
        return y;
    }
    // |d(C p)/dr| <= 2 kMaxCrosstalk per row inside the cube: each step shrinks the error at least
    // 2.5-fold (by about 100-fold at a real panel's 0.5 %).
    glm::dvec3 r = clamp ? glm::clamp(y, 0.0, 1.0) : y;
    for (int i = 0; i < kCrosstalkSteps; ++i) {
        r = y - crosstalk * crosstalkProducts(r);
        if (clamp) {
            r = glm::clamp(r, 0.0, 1.0);
        }
    }
    return r;
}

glm::dvec3 DisplayModel::forward(const glm::dvec3& counts) const
{
    return blackXyz + matrix * interacted(linearFromCounts(counts));
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
    for (int row = 0; row < 3; ++row) {
        double sum = 0.0;
        for (int col = 0; col < 3; ++col) {
            sum += std::abs(crosstalk[col][row]);
        }
        if (!(sum <= kMaxCrosstalk)) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("display profile '{}': crosstalk row {} has absolute sum "
                                         "{} (must be finite and at most {})",
                                         name, kNames[static_cast<std::size_t>(row)], sum,
                                         kMaxCrosstalk));
        }
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
