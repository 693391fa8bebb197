// Flare subtraction with a clamp count.
#include <pipeline/shading/frame.h>

namespace replica::pipeline::shading {

colour::Xyz subtractFlare(const colour::Xyz& surface, const colour::Xyz& flare, long& clamped)
{
    colour::Xyz out = surface - flare;
    for (int k = 0; k < 3; ++k) {
        if (out[k] < 0.0) {
            out[k] = 0.0;
            ++clamped;
        }
    }
    return out;
}

} // namespace replica::pipeline::shading
