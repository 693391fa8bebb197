// The booth dimmer (issue 24): one recorded luminance scale applied to every booth light, as a
// gallery dims its lights so that what it shows fits the display. Chosen in the site file
// ([booth] dimmer = <number> | "auto"); "auto" picks the scale from the scene itself, once, when
// the appliance is built, and the chosen number is what the session records (a replay never
// chooses again). Recordings made before it have no dimmer and replay at scale 1.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/display/display_inverse.h>
#include <pipeline/shading/frame.h>

namespace replica::platform {

// The 'quantile' of Y over the pixels of all 'frames' together (linear between order
// statistics at rank q (n - 1)); 0 without pixels.
double quantileY(const std::vector<pipeline::shading::XyzFrame>& frames, double quantile);

// The scale in (0, 1] that brings the 'quantile' (of the pixels of all 'frames' together) of the
// surface's Y to the panel's peak Y: min(1, peakY / Y_q). The quantile rather than the maximum,
// so that a few specular highlights do not darken the whole scene (they are gamut-mapped, as
// without a dimmer). 1 when the frames are dark or peakY is not positive.
double autoBoothDimmer(const std::vector<pipeline::shading::XyzFrame>& frames,
                       double peakY,
                       double quantile = 0.99);

// One view of pass 1's frame as the display pass meets it: where each pixel lies on the panel
// (metres, booth frame; row-major like the frame), the panel's normal and the eye.
struct DimmerView {
    pipeline::shading::XyzFrame frame;
    std::vector<glm::dvec3> pixelM;
    glm::dvec3 normal{0.0, 0.0, 1.0};
    glm::dvec3 eyeM{0.0};
};

// What the display pass asks the panel to emit for each pixel of the view (display_main.glsl):
// pass 1's XYZ divided by the viewing-angle gain at the pixel's angle to the eye (none when
// 'viewingCompensation' is off or the profile has no table). The pass also subtracts the screen's
// flare (rho_d E / pi: about 1 cd/m^2 at 2000 lux, against a peak of 900); it is left in, so the
// demand errs high by that. A pixel is above the panel's peak as the run summary counts it
// (GamutClass::OverPeak: the demand's Y over the white's) exactly when its demand's Y is.
pipeline::shading::XyzFrame panelDemand(const DimmerView& view,
                                        const pipeline::display::DisplayModel& model,
                                        bool viewingCompensation);

// The share of the frame's pixels whose Y, times 'scale', is above peakY (the run summary's
// "above the panel's peak" for a demand frame).
double overPeakFraction(const pipeline::shading::XyzFrame& frame, double scale, double peakY);

// What a dimmer does to what the panel can show of pass 1's frame: every pixel's XYZ scaled by
// 'scale', through the display's inverse (hue-keeping gamut mapping) and back through its model
// (black + M r), against the scaled XYZ, in CIELAB relative to the frame's white scaled likewise
// (the viewer adapts to the dimmed booth). The error the display adds; the renderer's own is
// separate (docs/accuracy.md).
struct DimmerEffect {
    double overPeakFraction = 0.0;   // pixels above the panel's peak
    double outOfGamutFraction = 0.0; // any gamut class but in gamut
    double de00Mean = 0.0;
    double de00P95 = 0.0;
    double de00Max = 0.0;
};
DimmerEffect boothDimmerEffect(const pipeline::shading::XyzFrame& frame,
                               double scale,
                               const pipeline::display::DisplayInverse& inverse);

} // namespace replica::platform
