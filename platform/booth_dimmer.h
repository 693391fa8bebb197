// The booth dimmer (issue 24): one recorded luminance scale applied to every booth light, as a
// gallery dims its lights so that what it shows fits the display. Chosen in the site file
// ([booth] dimmer = <number> | "auto"); "auto" picks the scale from the scene itself, once, when
// the appliance is built, and the chosen number is what the session records (a replay never
// chooses again). Recordings made before it have no dimmer and replay at scale 1.
#pragma once

#include <vector>

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
