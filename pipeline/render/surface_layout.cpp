// Where the surface lies in a booth frame.
#include <algorithm>
#include <cmath>
#include <utility>

#include <pipeline/render/surface_layout.h>

namespace replica::pipeline::render {

SurfaceLayout layoutOnPanel(const surface::SurfaceScene& scene, const scene::StandModel& stand)
{
    SurfaceLayout l;
    if (scene.widthM > 0.0 && scene.heightM > 0.0) {
        l.scale = {stand.panelWidthM / scene.widthM, stand.panelHeightM / scene.heightM};
        l.offset = {0.5 - 0.5 * l.scale.x, 0.5 - 0.5 * l.scale.y};
    }
    return l;
}

PixelRect surfaceRect(const SurfaceLayout& layout, int width, int height)
{
    if (!(layout.scale.x > 0.0) || !(layout.scale.y > 0.0)) {
        return {0, 0, width, height};
    }
    const auto span = [](double offset, double scale, int n) {
        const double a = (0.0 - offset) / scale * n;
        const double b = (1.0 - offset) / scale * n;
        const int lo = std::clamp(static_cast<int>(std::floor(std::min(a, b))) - 1, 0, n);
        const int hi = std::clamp(static_cast<int>(std::ceil(std::max(a, b))) + 1, 0, n);
        return std::pair<int, int>(lo, hi);
    };
    const auto [x0, x1] = span(layout.offset.x, layout.scale.x, width);
    const auto [r0, r1] = span(layout.offset.y, layout.scale.y, height); // rows down
    return {x0, height - r1, x1 - x0, r1 - r0};
}

} // namespace replica::pipeline::render
