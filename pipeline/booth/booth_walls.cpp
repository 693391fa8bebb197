// The booth's box and its patches.
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include <pipeline/booth/booth_walls.h>

namespace replica::pipeline::booth {
namespace {

// The rectangle origin + s u + t v cut into n x m patches of at most patchM on a side.
void addPatches(const Vec3& origin,
                const Vec3& u,
                const Vec3& v,
                double patchM,
                std::vector<WallPatch>& out)
{
    const double lu = glm::length(u);
    const double lv = glm::length(v);
    if (!(lu > 0.0) || !(lv > 0.0)) {
        return;
    }
    const int n = std::max(1, static_cast<int>(std::ceil(lu / patchM - 1e-9)));
    const int m = std::max(1, static_cast<int>(std::ceil(lv / patchM - 1e-9)));
    const Vec3 du = u / static_cast<double>(n);
    const Vec3 dv = v / static_cast<double>(m);
    const Vec3 normal = glm::normalize(glm::cross(u, v));
    for (int j = 0; j < m; ++j) {
        for (int i = 0; i < n; ++i) {
            WallPatch p;
            p.origin = origin + static_cast<double>(i) * du + static_cast<double>(j) * dv;
            p.u = du;
            p.v = dv;
            p.normal = normal;
            p.areaM2 = glm::length(glm::cross(du, dv));
            out.push_back(p);
        }
    }
}

} // namespace

BoothWalls defaultWalls(const BoothLight& ceiling, double backZ)
{
    BoothWalls w;
    Vec3 lo(1e300);
    Vec3 hi(-1e300);
    for (const double s : {-0.5, 0.5}) {
        for (const double t : {-0.5, 0.5}) {
            const Vec3 c = ceiling.centre + s * ceiling.edgeU + t * ceiling.edgeV;
            lo = glm::min(lo, c);
            hi = glm::max(hi, c);
        }
    }
    w.boxMin = Vec3(lo.x, 0.0, std::min(lo.z, backZ));
    w.boxMax = Vec3(hi.x, hi.y, hi.z);
    w.reflectance = colour::Spectrum::constant(kMunsellN7Reflectance);
    return w;
}

std::vector<WallPatch> wallPatches(const BoothWalls& walls, double patchM)
{
    const Vec3 a = walls.boxMin;
    const Vec3 b = walls.boxMax;
    const Vec3 dx(b.x - a.x, 0.0, 0.0);
    const Vec3 dy(0.0, b.y - a.y, 0.0);
    const Vec3 dz(0.0, 0.0, b.z - a.z);
    std::vector<WallPatch> out;
    addPatches(a, dz, dx, patchM, out);                   // floor: z x x = +y
    addPatches(a, dx, dy, patchM, out);                   // back: x x y = +z
    addPatches(a, dy, dz, patchM, out);                   // left: y x z = +x
    addPatches(Vec3(b.x, a.y, a.z), dz, dy, patchM, out); // right: z x y = -x
    return out;
}

} // namespace replica::pipeline::booth
