// Inverse display model.
#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/matrix.hpp>

#include <pipeline/display/display_inverse.h>

namespace replica::pipeline::display {

Expected<DisplayInverse> DisplayInverse::build(const DisplayModel& model, int lutSize)
{
    if (auto ok = model.validate(); !ok) {
        return tl::unexpected(ok.error());
    }
    if (lutSize < 16 || lutSize > 65536) {
        return makeError(ErrorCode::InvalidArgument, "display inverse: LUT size must be 16..65536");
    }
    DisplayInverse inv;
    inv.model_ = model;
    inv.geometry_.xyzToLinear = glm::inverse(model.matrix);
    inv.geometry_.blackXyz = model.blackXyz;
    inv.geometry_.blackY = model.blackXyz.y;
    inv.geometry_.whiteY = model.whiteXyz().y;
    inv.geometry_.edgeTolerance = model.gamutEdgeTolerance;
    inv.geometry_.edgeFloor = model.gamutEdgeFloor;
    inv.lutSize_ = lutSize;
    const double maxCount = model.maxCount();
    for (std::size_t c = 0; c < 3; ++c) {
        auto& lut = inv.lut_[c];
        lut.resize(static_cast<std::size_t>(lutSize));
        for (int j = 0; j < lutSize; ++j) {
            // The cube-root domain puts a quarter of the entries below r = 0.016 (about count 40
            // at gamma 2.2), where the inverse is steepest.
            const double u = static_cast<double>(j) / static_cast<double>(lutSize - 1);
            lut[static_cast<std::size_t>(j)] = model.tone[c].inverse(u * u * u) / maxCount;
        }
    }
    return inv;
}

const std::vector<double>& DisplayInverse::lut(int channel) const
{
    return lut_[static_cast<std::size_t>(std::clamp(channel, 0, 2))];
}

double DisplayInverse::countsFromLinear(int channel, double r, ToneInverse tone) const
{
    const auto c = static_cast<std::size_t>(std::clamp(channel, 0, 2));
    const double rc = std::clamp(std::isfinite(r) ? r : 0.0, 0.0, 1.0);
    if (tone == ToneInverse::Exact) {
        return model_.tone[c].inverse(rc);
    }
    const auto& lut = lut_[c];
    const double pos = std::cbrt(rc) * static_cast<double>(lutSize_ - 1);
    const auto j = static_cast<std::size_t>(
            std::clamp(std::floor(pos), 0.0, static_cast<double>(lutSize_ - 2)));
    const double f = pos - static_cast<double>(j);
    // lut[j] + 1 * (lut[j + 1] - lut[j]) can round past lut[j + 1] at the table's top.
    return std::clamp((lut[j] + f * (lut[j + 1] - lut[j])) * model_.maxCount(), 0.0,
                      model_.maxCount());
}

InverseResult DisplayInverse::invert(const glm::dvec3& xyz, GamutMode mode, ToneInverse tone) const
{
    InverseResult out;
    if (model_.hasCrosstalk()) {
        // With crosstalk the gamut is the cube in r, not in y = M^-1 (XYZ - black): a colour
        // whose r (the crosstalk undone) lies in [0, 1]^3 is in gamut as it is. (The uniform
        // loss puts some colours the panel makes a hair outside the y cube.)
        const glm::dvec3 r =
                model_.deinteracted(geometry_.xyzToLinear * (xyz - geometry_.blackXyz), false);
        constexpr double kTol = 1e-9; // mapToGamut's
        if (r.x >= -kTol && r.y >= -kTol && r.z >= -kTol && r.x <= 1.0 + kTol &&
            r.y <= 1.0 + kTol && r.z <= 1.0 + kTol && xyz.y >= geometry_.blackY) {
            out.linear = glm::clamp(r, 0.0, 1.0);
            for (int c = 0; c < 3; ++c) {
                out.counts[c] = countsFromLinear(c, out.linear[c], tone);
            }
            return out;
        }
    }
    const MappedLinear m = mapToGamut(geometry_, xyz, mode);
    // The mapping works on the additive part, y = M^-1 (XYZ - black); the crosstalk is undone
    // after it (C = 0: r = y).
    out.linear = model_.deinteracted(m.r);
    out.gamutClass = m.gamutClass;
    for (int c = 0; c < 3; ++c) {
        out.counts[c] = countsFromLinear(c, out.linear[c], tone);
    }
    return out;
}

DisplayLut3d DisplayLut3d::build(const DisplayInverse& inverse, int size)
{
    DisplayLut3d lut;
    lut.size_ = std::max(size, 2);
    const glm::dvec3 white = inverse.model().whiteXyz();
    lut.scale_ = 1.0 / white;
    const auto n = static_cast<std::size_t>(lut.size_);
    lut.nodes_.resize(n * n * n);
    for (std::size_t k = 0; k < n; ++k) {
        for (std::size_t j = 0; j < n; ++j) {
            for (std::size_t i = 0; i < n; ++i) {
                const glm::dvec3 u = glm::dvec3(static_cast<double>(i), static_cast<double>(j),
                                                static_cast<double>(k)) /
                                     static_cast<double>(n - 1);
                const glm::dvec3 xyz = u * u * u * white;
                lut.nodes_[(k * n + j) * n + i] =
                        inverse.invert(xyz, GamutMode::HueKeeping, ToneInverse::Exact).counts;
            }
        }
    }
    return lut;
}

glm::dvec3 DisplayLut3d::counts(const glm::dvec3& xyz) const
{
    const auto n = static_cast<std::size_t>(size_);
    const double top = static_cast<double>(size_ - 1);
    glm::dvec3 p;
    std::array<std::size_t, 3> i0{};
    for (int a = 0; a < 3; ++a) {
        const double v = std::isfinite(xyz[a]) ? std::max(xyz[a] * scale_[a], 0.0) : 0.0;
        const double pos = std::clamp(std::cbrt(v), 0.0, 1.0) * top;
        const double fl = std::min(std::floor(pos), top - 1.0);
        i0[static_cast<std::size_t>(a)] = static_cast<std::size_t>(fl);
        p[a] = pos - fl;
    }
    auto node = [&](std::size_t di, std::size_t dj, std::size_t dk) {
        return nodes_[((i0[2] + dk) * n + (i0[1] + dj)) * n + (i0[0] + di)];
    };
    // Tetrahedral interpolation: walk from the cell's origin to its far corner along the axes in
    // decreasing order of the fractional coordinates.
    std::array<int, 3> order{0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int a, int b) { return p[a] > p[b]; });
    std::array<std::size_t, 3> step{0, 0, 0};
    glm::dvec3 prev = node(0, 0, 0);
    glm::dvec3 result = prev;
    for (int s = 0; s < 3; ++s) {
        step[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])] = 1;
        const glm::dvec3 next = node(step[0], step[1], step[2]);
        result += p[order[static_cast<std::size_t>(s)]] * (next - prev);
        prev = next;
    }
    return result;
}

} // namespace replica::pipeline::display
