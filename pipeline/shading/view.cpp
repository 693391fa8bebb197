// Panel pose from the hinge and the mapping of pixels to surface points.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/base/bilinear.h>
#include <pipeline/shading/view.h>

namespace replica::pipeline::shading {

Vec3 sampleNormal(const std::vector<Vec3>& normals, int w, int h, double x, double y)
{
    const Vec3 n = bilinearAtTexel(x, y, [&](int ix, int iy) {
        ix = std::clamp(ix, 0, w - 1);
        iy = std::clamp(iy, 0, h - 1);
        return normals[static_cast<std::size_t>(iy) * w + ix];
    });
    const double len = glm::length(n);
    return len > 1e-12 ? n / len : Vec3(0.0, 0.0, 1.0);
}

ShadingPoint shadingPoint(const View& view,
                          const surface::SurfaceScene& scene,
                          const std::vector<Vec3>& normals,
                          int px,
                          int py)
{
    // The texel position with the division last: exact wherever the pixel centre lies on a
    // texel edge, which then takes the texel after it (the GL pass's rule too). u * texels
    // rounds such a centre either way.
    const glm::dvec2 texel((px + 0.5) * scene.width / view.pixelsX,
                           (py + 0.5) * scene.height / view.pixelsY);
    return shadingPointAt(view, scene, normals, (px + 0.5) / view.pixelsX,
                          (py + 0.5) / view.pixelsY, texel);
}

ShadingPoint shadingPointAt(const View& view,
                            const surface::SurfaceScene& scene,
                            const std::vector<Vec3>& normals,
                            double u,
                            double v,
                            const std::optional<glm::dvec2>& texel)
{
    ShadingPoint s;
    const PanelPose& pose = view.panel;
    s.p = pose.centre + pose.right * ((u - 0.5) * scene.widthM) +
          pose.up * ((0.5 - v) * scene.heightM);
    s.nGeo = pose.normal;
    s.right = pose.right;
    s.up = pose.up;
    s.texX = texel ? texel->x : u * scene.width;
    s.texY = texel ? texel->y : v * scene.height;
    s.tx = std::clamp(static_cast<int>(s.texX), 0, scene.width - 1);
    s.ty = std::clamp(static_cast<int>(s.texY), 0, scene.height - 1);
    if (normals.empty()) {
        s.nShade = s.nGeo;
    } else {
        const Vec3 nl = sampleNormal(normals, scene.width, scene.height, s.texX, s.texY);
        s.nShade = glm::normalize(pose.right * nl.x + pose.up * nl.y + pose.normal * nl.z);
    }
    return s;
}

bool eyeBehind(const View& view, const ShadingPoint& sp)
{
    const Vec3 toEye = view.eye - sp.p;
    const double eyeDist = glm::length(toEye);
    const Vec3 unit = eyeDist > 0.0 ? toEye / eyeDist : sp.nGeo;
    return !(glm::dot(unit, sp.nGeo) > 0.0);
}

} // namespace replica::pipeline::shading
