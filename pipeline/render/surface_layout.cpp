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

namespace {

// Where the surface's two edges along one axis fall in a frame n pixels across, in pixels, the
// lower first: the pixel coordinates at which surface u (or v) is 0 and 1.
std::pair<double, double> surfaceEdges(double offset, double scale, int n)
{
    const double a = (0.0 - offset) / scale * n;
    const double b = (1.0 - offset) / scale * n;
    return {std::min(a, b), std::max(a, b)};
}

} // namespace

PixelRect surfaceRect(const SurfaceLayout& layout, int width, int height)
{
    if (!(layout.scale.x > 0.0) || !(layout.scale.y > 0.0)) {
        return {0, 0, width, height};
    }
    const auto span = [](double offset, double scale, int n) {
        const auto [a, b] = surfaceEdges(offset, scale, n);
        const int lo = std::clamp(static_cast<int>(std::floor(a)) - 1, 0, n);
        const int hi = std::clamp(static_cast<int>(std::ceil(b)) + 1, 0, n);
        return std::pair<int, int>(lo, hi);
    };
    const auto [x0, x1] = span(layout.offset.x, layout.scale.x, width);
    const auto [r0, r1] = span(layout.offset.y, layout.scale.y, height); // rows down
    return {x0, height - r1, x1 - x0, r1 - r0};
}

PixelRect surfaceInterior(const SurfaceLayout& layout, int width, int height)
{
    if (!(layout.scale.x > 0.0) || !(layout.scale.y > 0.0)) {
        return {0, 0, 0, 0};
    }
    // Pixel i's centre is i + 0.5; the surface spans [a, b] in pixels: the pixels whose centres
    // lie in [a + 0.5, b - 0.5], that is the whole pixel on the surface (float's rounding of the
    // shader's bounds test is some 1e-4 of a pixel here).
    const auto span = [](double offset, double scale, int n) {
        const auto [a, b] = surfaceEdges(offset, scale, n);
        if (!std::isfinite(a) || !std::isfinite(b)) {
            return std::pair<int, int>(0, 0); // no pixel is certain
        }
        const double lo = std::ceil(a);
        const double hi = std::floor(b);
        const int l = static_cast<int>(std::clamp(lo, 0.0, static_cast<double>(n)));
        const int h = static_cast<int>(std::clamp(hi, 0.0, static_cast<double>(n)));
        return std::pair<int, int>(l, std::max(h, l));
    };
    const auto [x0, x1] = span(layout.offset.x, layout.scale.x, width);
    const auto [r0, r1] = span(layout.offset.y, layout.scale.y, height); // rows down
    if (x1 == x0 || r1 == r0) {
        return {0, 0, 0, 0};
    }
    return {x0, height - r1, x1 - x0, r1 - r0};
}

} // namespace replica::pipeline::render
