// The per-frame CIEDE2000 error statistics the sweep reports against the reference. CIELAB and
// CIEDE2000 themselves are colour::xyzToLab and colour::ciede2000 (pipeline/colour/).
#pragma once

#include <pipeline/colour/xyz.h>
#include <pipeline/shading/frame.h>

namespace replica::pipeline::reference {

struct FrameError {
    double mean = 0.0;
    double p95 = 0.0;
    double max = 0.0;
};

// Lab white: the reference frame's white (a perfect diffuser at the panel centre under the same
// light).
FrameError compareFrames(const shading::XyzFrame& reference, const shading::XyzFrame& test);

} // namespace replica::pipeline::reference
