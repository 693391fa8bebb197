#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/display/viewing_angle.h>
#include <platform/booth_dimmer.h>

namespace replica::platform {

namespace {

// Linear between order statistics at rank q (n - 1) of sorted values.
double sortedQuantile(const std::vector<double>& v, double q)
{
    if (v.empty()) {
        return 0.0;
    }
    const double r = std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1);
    const auto i = static_cast<std::size_t>(std::floor(r));
    const std::size_t j = std::min(i + 1, v.size() - 1);
    return v[i] + (r - static_cast<double>(i)) * (v[j] - v[i]);
}

} // namespace

double quantileY(const std::vector<pipeline::shading::XyzFrame>& frames, double quantile)
{
    std::vector<double> y;
    for (const auto& f : frames) {
        for (const auto& p : f.xyz) {
            if (std::isfinite(p.y)) {
                y.push_back(p.y);
            }
        }
    }
    std::sort(y.begin(), y.end());
    return sortedQuantile(y, quantile);
}

double autoBoothDimmer(const std::vector<pipeline::shading::XyzFrame>& frames,
                       double peakY,
                       double quantile)
{
    const double yq = quantileY(frames, quantile);
    if (!(peakY > 0.0) || !(yq > peakY)) {
        return 1.0;
    }
    return peakY / yq;
}

pipeline::shading::XyzFrame panelDemand(const DimmerView& view,
                                        const pipeline::display::DisplayModel& model,
                                        bool viewingCompensation)
{
    namespace pd = pipeline::display;
    pipeline::shading::XyzFrame out = view.frame;
    if (!viewingCompensation || model.viewing.empty()) {
        return out;
    }
    const glm::dvec3 white = model.whiteXyz();
    for (std::size_t i = 0; i < out.xyz.size() && i < view.pixelM.size(); ++i) {
        const double angle = pd::viewingAngleDeg(view.pixelM[i], view.normal, view.eyeM);
        // The shader's floor on the gain (display_main.glsl).
        const glm::dvec3 gain =
                glm::max(pd::viewingGain(model.viewing, white, angle), glm::dvec3(1e-3));
        out.xyz[i] /= gain;
    }
    return out;
}

double overPeakFraction(const pipeline::shading::XyzFrame& frame, double scale, double peakY)
{
    if (frame.xyz.empty()) {
        return 0.0;
    }
    long over = 0;
    for (const auto& p : frame.xyz) {
        over += scale * p.y > peakY ? 1 : 0;
    }
    return static_cast<double>(over) / static_cast<double>(frame.xyz.size());
}

DimmerEffect boothDimmerEffect(const pipeline::shading::XyzFrame& frame,
                               double scale,
                               const pipeline::display::DisplayInverse& inverse)
{
    namespace pd = pipeline::display;
    DimmerEffect e;
    const pd::DisplayModel& m = inverse.model();
    const glm::dvec3 white = scale * frame.whiteXyz;
    if (frame.xyz.empty() || !(white.y > 0.0)) {
        return e;
    }
    std::vector<double> de;
    de.reserve(frame.xyz.size());
    long over = 0, out = 0;
    for (const auto& p : frame.xyz) {
        const glm::dvec3 want = scale * glm::dvec3(p);
        const pd::InverseResult r = inverse.invert(want, pd::GamutMode::HueKeeping);
        over += r.gamutClass == pd::GamutClass::OverPeak ? 1 : 0;
        out += r.inGamut() ? 0 : 1;
        const glm::dvec3 shown = m.blackXyz + m.matrix * m.interacted(r.linear);
        de.push_back(pipeline::colour::ciede2000(pipeline::colour::xyzToLab(want, white),
                                                 pipeline::colour::xyzToLab(shown, white)));
    }
    const double n = static_cast<double>(frame.xyz.size());
    e.overPeakFraction = static_cast<double>(over) / n;
    e.outOfGamutFraction = static_cast<double>(out) / n;
    double sum = 0.0;
    for (const double d : de) {
        sum += d;
    }
    e.de00Mean = sum / n;
    std::sort(de.begin(), de.end());
    e.de00P95 = sortedQuantile(de, 0.95);
    e.de00Max = de.back();
    return e;
}

} // namespace replica::platform
