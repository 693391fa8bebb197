// Per-frame CIEDE2000 statistics in double, through colour::xyzToLab and colour::ciede2000.
#include <algorithm>
#include <cmath>
#include <vector>

#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/reference/frame_error.h>

namespace replica::pipeline::reference {

FrameError compareFrames(const shading::XyzFrame& reference, const shading::XyzFrame& test)
{
    FrameError e;
    const std::size_t n = std::min(reference.xyz.size(), test.xyz.size());
    if (n == 0) {
        return e;
    }
    std::vector<double> d(n);
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        d[k] = colour::ciede2000(colour::xyzToLab(reference.xyz[k], reference.whiteXyz),
                                 colour::xyzToLab(test.xyz[k], reference.whiteXyz));
        sum += d[k];
    }
    e.mean = sum / static_cast<double>(n);
    std::sort(d.begin(), d.end());
    e.max = d.back();
    e.p95 = d[std::min(n - 1,
                       static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n))) - 1)];
    return e;
}

} // namespace replica::pipeline::reference
