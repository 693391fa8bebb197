// The inverse display model: absolute XYZ -> real-valued counts, by the analytic path (M^-1, then
// per-channel inverse tone curves tabulated densely in the cube-root domain) with hue-keeping
// gamut mapping (on y = M^-1 (XYZ - black); a crosstalk term is then undone by fixed-point steps,
// DisplayModel::deinteracted), and a 3-D LUT alternative kept for comparison (docs/display.md has
// both measured).
#pragma once

#include <array>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/display/display_model.h>
#include <pipeline/display/gamut_map.h>

namespace replica::pipeline::display {

// How a channel's r is turned into counts.
enum class ToneInverse {
    Exact, // bisection on the monotone tone curve (reference; CPU only)
    Lut,   // the dense table the shader uses, linear interpolation in u = cbrt(r)
};

struct InverseResult {
    glm::dvec3 counts{0.0}; // real-valued, in [0, maxCount], before quantisation
    glm::dvec3 linear{0.0}; // r after gamut mapping (and the crosstalk undone)
    GamutClass gamutClass = GamutClass::InGamut;
    bool inGamut() const { return gamutClass == GamutClass::InGamut; }
};

class DisplayInverse
{
public:
    static constexpr int kDefaultLutSize = 4096;

    // Fails when the model does not validate.
    static Expected<DisplayInverse> build(const DisplayModel& model, int lutSize = kDefaultLutSize);

    InverseResult invert(const glm::dvec3& xyz,
                         GamutMode mode = GamutMode::HueKeeping,
                         ToneInverse tone = ToneInverse::Lut) const;

    // r -> counts for one channel.
    double countsFromLinear(int channel, double r, ToneInverse tone) const;

    const DisplayModel& model() const { return model_; }
    const GamutGeometry& geometry() const { return geometry_; }
    int lutSize() const { return lutSize_; }
    // lut(c)[j] = counts / maxCount at r = (j / (lutSize - 1))^3.
    const std::vector<double>& lut(int channel) const;

private:
    DisplayModel model_;
    GamutGeometry geometry_;
    int lutSize_ = 0;
    std::array<std::vector<double>, 3> lut_;
};

// The 3-D LUT variant: a lattice over u = cbrt(XYZ / white XYZ) per axis in [0, 1] holding the
// analytic path's counts (hue-keeping, exact tone inverse); tetrahedral interpolation.
class DisplayLut3d
{
public:
    static DisplayLut3d build(const DisplayInverse& inverse, int size = 33);
    glm::dvec3 counts(const glm::dvec3& xyz) const;
    int size() const { return size_; }
    // Node (i, j, k) at index (k * size + j) * size + i, counts; and the per-axis 1 / white XYZ.
    const std::vector<glm::dvec3>& nodes() const { return nodes_; }
    const glm::dvec3& scale() const { return scale_; }

private:
    int size_ = 0;
    glm::dvec3 scale_{1.0}; // 1 / white XYZ
    std::vector<glm::dvec3> nodes_;
};

} // namespace replica::pipeline::display
