// Nominal sRGB-like display.
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include <pipeline/display/nominal_display.h>

namespace replica::pipeline::display {

DisplayModel nominalDisplayModel(const std::string& name, double peakWhiteCdM2, double blackCdM2)
{
    // IEC 61966-2-1 linear sRGB to XYZ (D65, white Y = 1); GLM matrices are column-major.
    const glm::dmat3 srgb{0.4124, 0.2126, 0.0193, 0.3576, 0.7152, 0.1192, 0.1805, 0.0722, 0.9505};
    DisplayModel m;
    m.name = name;
    m.description = fmt::format("nominal sRGB-like panel, {} cd/m^2 peak, {} cd/m^2 black, gamma "
                                "2.2: NOT a characterisation (--uncalibrated)",
                                peakWhiteCdM2, blackCdM2);
    m.bitDepth = 8;
    m.matrix = srgb * (peakWhiteCdM2 - blackCdM2);
    m.blackXyz = glm::dvec3{0.9505, 1.0, 1.0890} * blackCdM2;
    // Every count is a knot, so the interpolating curve is the power law at each count.
    std::vector<double> counts;
    std::vector<double> values;
    for (int d = 0; d <= 255; ++d) {
        counts.push_back(d);
        values.push_back(std::pow(d / 255.0, 2.2));
    }
    for (auto& t : m.tone) {
        t = ToneCurve(counts, values);
    }
    return m;
}

} // namespace replica::pipeline::display
