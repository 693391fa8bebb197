// Hue-keeping gamut mapping.
#include <algorithm>
#include <cmath>

#include <pipeline/display/gamut_map.h>

namespace replica::pipeline::display {

void GamutCounters::add(GamutClass c)
{
    ++pixels;
    switch (c) {
    case GamutClass::InGamut:
        break;
    case GamutClass::Chroma:
        ++chroma;
        break;
    case GamutClass::OverPeak:
        ++overPeak;
        break;
    case GamutClass::BelowBlack:
        ++belowBlack;
        break;
    }
}

double GamutCounters::outOfGamutFraction() const
{
    return pixels == 0 ? 0.0 : static_cast<double>(outOfGamut()) / static_cast<double>(pixels);
}

double GamutCounters::surfaceOutOfGamutFraction() const
{
    if (surfacePixels == 0) {
        return outOfGamutFraction();
    }
    return static_cast<double>(surfaceChroma + surfaceOverPeak + surfaceBelowBlack) /
           static_cast<double>(surfacePixels);
}

double GamutCounters::surfaceOverPeakFraction() const
{
    if (surfacePixels == 0) {
        return pixels == 0 ? 0.0 : static_cast<double>(overPeak) / static_cast<double>(pixels);
    }
    return static_cast<double>(surfaceOverPeak) / static_cast<double>(surfacePixels);
}

MappedLinear
mapToGamut(const GamutGeometry& g, const glm::dvec3& xyzIn, GamutMode mode, double tolerance)
{
    MappedLinear out;
    if (!std::isfinite(xyzIn.x) || !std::isfinite(xyzIn.y) || !std::isfinite(xyzIn.z)) {
        out.gamutClass = GamutClass::BelowBlack;
        return out;
    }
    glm::dvec3 xyz = xyzIn;
    bool overPeak = false;
    const double edge = g.edgeTolerance;
    if (xyz.y > g.whiteY) {
        // Scale to peak luminance: chromaticity kept. (Clip mode leaves it for the clip below;
        // within the edge tolerance of peak the channels are clamped below.)
        overPeak = true;
        if (mode == GamutMode::HueKeeping && xyz.y > g.whiteY * (1.0 + edge)) {
            xyz *= g.whiteY / xyz.y;
        }
    }
    const glm::dvec3 r = g.xyzToLinear * (xyz - g.blackXyz);
    const double span = g.whiteY - g.blackY;
    if (!(xyz.y - g.blackY >= 0.0) || !(span > 0.0)) {
        out.gamutClass = GamutClass::BelowBlack;
        if (mode == GamutMode::Clip) {
            out.r = glm::clamp(r, 0.0, 1.0);
        }
        return out;
    }
    const bool inside = r.x >= -tolerance && r.y >= -tolerance && r.z >= -tolerance &&
                        r.x <= 1.0 + tolerance && r.y <= 1.0 + tolerance && r.z <= 1.0 + tolerance;
    // Within the fit's uncertainty of the gamut (the edge tolerance; below 0 relative to the
    // colour's largest channel, since the fit's error in r scales with the colour): clamped per
    // channel like an in-gamut colour, though still counted as outside.
    const double low = std::max(tolerance, edge * std::max({r.x, r.y, r.z, 0.0}) + g.edgeFloor);
    const double high = std::max(tolerance, edge);
    const bool near = r.x >= -low && r.y >= -low && r.z >= -low && r.x <= 1.0 + high &&
                      r.y <= 1.0 + high && r.z <= 1.0 + high;
    if (inside || near || mode == GamutMode::Clip) {
        out.r = glm::clamp(r, 0.0, 1.0);
        out.gamutClass = overPeak ? GamutClass::OverPeak
                                  : (inside ? GamutClass::InGamut : GamutClass::Chroma);
        return out;
    }
    // (a) A chromaticity outside the primaries' triangle (some r < 0): towards the neutral of the
    // same luminance until no channel is negative. M_Y g = Y - Y_k because M (1,1,1) = white -
    // black, so the line keeps luminance and dominant wavelength.
    const double s = std::clamp((xyz.y - g.blackY) / span, 0.0, 1.0);
    double t = 1.0;
    for (int c = 0; c < 3; ++c) {
        if (r[c] < 0.0) {
            t = std::min(t, s / (s - r[c]));
        }
    }
    glm::dvec3 m = glm::dvec3(s) + std::clamp(t, 0.0, 1.0) * (r - glm::dvec3(s));
    // (b) A reachable chromaticity too bright for the panel there (some r > 1): scale the light
    // above black down, which keeps its chromaticity and gives up only luminance.
    const double top = std::max({m.x, m.y, m.z});
    if (top > 1.0) {
        m /= top;
    }
    out.r = glm::clamp(m, 0.0, 1.0);
    out.gamutClass = overPeak ? GamutClass::OverPeak : GamutClass::Chroma;
    return out;
}

} // namespace replica::pipeline::display
