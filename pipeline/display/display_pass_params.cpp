// Shader parameters of the inverse display model (its GLSL: pipeline/render/glsl/display_*.glsl).
#include <algorithm>

#include <glm/matrix.hpp>

#include <pipeline/display/display_pass_params.h>
#include <pipeline/display/viewing_angle.h>

namespace replica::pipeline::display {

DisplayPassParams makeDisplayPassParams(const DisplayInverse& inverse)
{
    const DisplayModel& m = inverse.model();
    const GamutGeometry& g = inverse.geometry();
    DisplayPassParams p;
    for (int col = 0; col < 3; ++col) {
        for (int row = 0; row < 3; ++row) {
            p.xyzToLinear[static_cast<std::size_t>(col * 3 + row)] =
                    static_cast<float>(g.xyzToLinear[col][row]);
        }
        p.blackXyz[static_cast<std::size_t>(col)] = static_cast<float>(g.blackXyz[col]);
    }
    p.blackY = static_cast<float>(g.blackY);
    p.whiteY = static_cast<float>(g.whiteY);
    p.gamutEdgeTolerance = static_cast<float>(g.edgeTolerance);
    p.gamutEdgeFloor = static_cast<float>(g.edgeFloor);
    const DisplayModel& model = inverse.model();
    if (model.hasCrosstalk()) {
        for (int col = 0; col < 3; ++col) {
            for (int row = 0; row < 3; ++row) {
                p.crosstalk[static_cast<std::size_t>(col * 3 + row)] =
                        static_cast<float>(model.crosstalk[col][row]);
            }
        }
        p.crosstalkSteps = DisplayModel::kCrosstalkSteps;
    }
    p.maxCount = static_cast<float>(m.maxCount());
    p.lutSize = inverse.lutSize();
    p.lut.reserve(static_cast<std::size_t>(p.lutSize - 1) * 3 * 2);
    for (int c = 0; c < 3; ++c) {
        const std::vector<double>& lut = inverse.lut(c);
        for (std::size_t j = 0; j + 1 < lut.size(); ++j) {
            p.lut.push_back(static_cast<float>(lut[j]));
            p.lut.push_back(static_cast<float>(lut[j + 1]));
        }
    }
    p.dither = ditherPattern();
    const glm::dvec3 white = m.whiteXyz();
    p.viewingRows =
            static_cast<int>(std::min<std::size_t>(m.viewing.angleDeg.size(), kMaxViewingRows));
    for (int i = 0; i < p.viewingRows; ++i) {
        const auto row = static_cast<std::size_t>(i);
        const glm::dvec3 gain = viewingGainAtRow(m.viewing, white, row);
        p.viewing[row * 4 + 0] = static_cast<float>(m.viewing.angleDeg[row]);
        p.viewing[row * 4 + 1] = static_cast<float>(gain.x);
        p.viewing[row * 4 + 2] = static_cast<float>(gain.y);
        p.viewing[row * 4 + 3] = static_cast<float>(gain.z);
    }
    if (p.viewingRows >= 2) {
        p.viewingGrid.reserve(4 * kViewingGridNodes);
        for (int k = 0; k < kViewingGridNodes; ++k) {
            const glm::dvec3 gain = viewingGain(m.viewing, white, k * kViewingGridStepDeg);
            p.viewingGrid.insert(p.viewingGrid.end(),
                                 {static_cast<float>(gain.x), static_cast<float>(gain.y),
                                  static_cast<float>(gain.z), 0.0f});
        }
    }
    p.flarePerLux =
            m.condition == MeasurementCondition::LitBooth
                    ? 0.0f
                    : static_cast<float>(m.frontSurfaceReflectance / 3.14159265358979323846);
    return p;
}

} // namespace replica::pipeline::display
