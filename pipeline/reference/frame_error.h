// CIELAB / CIEDE2000 and the per-frame error statistics the sweep reports against the reference.
#pragma once

#include <pipeline/colour/xyz.h>
#include <pipeline/shading/frame.h>

namespace replica::pipeline::reference {

struct Lab {
    double l = 0.0, a = 0.0, b = 0.0;
};

// CIELAB with the cube-root branch at (6/29)^3 = 216/24389; white must have Y > 0 (else black).
Lab xyzToLab(const colour::Xyz& xyz, const colour::Xyz& white);

// CIEDE2000 (Sharma, Wu & Dalal 2005 formulation), kL = kC = kH = 1; handles zero chroma and the
// hue wrap-around.
double ciede2000(const Lab& a, const Lab& b);

struct FrameError {
    double mean = 0.0;
    double p95 = 0.0;
    double max = 0.0;
};

// Lab white: the reference frame's white (a perfect diffuser at the panel centre under the same
// light).
FrameError compareFrames(const shading::XyzFrame& reference, const shading::XyzFrame& test);

} // namespace replica::pipeline::reference
