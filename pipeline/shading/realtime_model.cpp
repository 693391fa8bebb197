// CPU model of the real-time renderer.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#include <glm/geometric.hpp>

#include <pipeline/shading/realtime_model.h>

namespace replica::pipeline::shading {
namespace {

// Soft horizon test of a direction at elevation sin = lz against the horizon sine sinB.
double elevationVisibility(double sinB, double lz, double softness)
{
    if (sinB <= 0.0) {
        return 1.0; // flat horizon: the geometric test already decided (keeps flat frames
                    // identical)
    }
    const double e0 = sinB - softness;
    const double e1 = sinB + softness;
    const double t = std::clamp((lz - e0) / std::max(e1 - e0, 1e-12), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// The horizon's softness for one point light: at least 'softness', and wide enough to cover the
// spread of the ceiling it stands for. Moving the light point by s along the ceiling moves its
// elevation sine (d.n, d the unit direction) by (s.n - (d.n)(d.s)) / |d|; over the region's
// spread (its standard deviation along each edge) that is sigma, and a uniform box of standard
// deviation sigma reaches sqrt(3) sigma either side. With one sharp step per point, a region
// straddling the relief's horizon went all dark or all lit where the reference sees part of it.
double lightSoftness(const booth::PointLight& l,
                     const Vec3& d,
                     const Vec3& n,
                     double cosG,
                     double d2,
                     double texelAreaM2,
                     double softness)
{
    // The distance floored at a texel, as in eq. (1): a light touching the surface stays finite.
    const double invDist = 1.0 / std::sqrt(std::max(d2, texelAreaM2));
    const double su = (glm::dot(l.spreadU, n) - cosG * glm::dot(d, l.spreadU)) * invDist;
    const double sv = (glm::dot(l.spreadV, n) - cosG * glm::dot(d, l.spreadV)) * invDist;
    return std::max(softness, std::sqrt(3.0 * (su * su + sv * sv)));
}

double horizonVisibility(const surface::HorizonMap* horizon,
                         int tx,
                         int ty,
                         const std::optional<glm::dvec2>& at,
                         const Vec3& l,
                         double softness)
{
    if (horizon == nullptr || horizon->directions <= 0) {
        return 1.0;
    }
    const double sinB =
            at ? horizon->sinHorizonBilinear(at->x, at->y, l) : horizon->sinHorizon(tx, ty, l);
    return elevationVisibility(sinB, l.z, softness);
}

// The relief's visibility of one light, the per-light set-up both eq. (1) sums share: the
// light's direction in the macro tangent frame (right, up, nGeo), its horizon softness
// (lightSoftness) and the horizon test at the texel or, with 'at', bilinear at that fractional
// texel position. 1 without a horizon map (what horizonVisibility returns there).
struct ReliefLightVisibility {
    // The horizon at sp: its texel's, or with 'bilinear' the bilinear one at (texX, texY)
    // (RenderSettings::horizonBilinear).
    ReliefLightVisibility(const ShadingPoint& sp,
                          const surface::HorizonMap* map,
                          bool bilinear,
                          double texelArea,
                          double horizonSoftness)
        : horizon(map), tx(sp.tx), ty(sp.ty),
          at(bilinear ? std::optional<glm::dvec2>({sp.texX, sp.texY}) : std::nullopt),
          right(sp.right), up(sp.up), nGeo(sp.nGeo), texelAreaM2(texelArea),
          softness(horizonSoftness)
    {}

    const surface::HorizonMap* horizon;
    int tx;
    int ty;
    std::optional<glm::dvec2> at;
    const Vec3& right;
    const Vec3& up;
    const Vec3& nGeo;
    double texelAreaM2;
    double softness;

    bool active() const { return horizon != nullptr && horizon->directions > 0; }

    // Along the unit direction d to the light, d2 the squared distance, cosG = nGeo . d.
    double along(const booth::PointLight& l, const Vec3& d, double d2, double cosG) const
    {
        if (!active()) {
            return 1.0;
        }
        const Vec3 lt(glm::dot(d, right), glm::dot(d, up), cosG);
        return horizonVisibility(horizon, tx, ty, at, lt,
                                 lightSoftness(l, d, nGeo, cosG, d2, texelAreaM2, softness));
    }

    // Along the direction from p to the light's position (a region's centroid): one test for the
    // whole region. 1 when p is at the centroid.
    double towards(const booth::PointLight& l, const Vec3& p) const
    {
        if (!active()) {
            return 1.0;
        }
        Vec3 d = l.position - p;
        const double d2 = glm::dot(d, d);
        if (!(d2 > 0.0)) {
            return 1.0;
        }
        d /= std::sqrt(d2);
        return along(l, d, d2, glm::dot(nGeo, d));
    }
};

} // namespace

double radicalInverse2(unsigned k)
{
    k = (k << 16u) | (k >> 16u);
    k = ((k & 0x55555555u) << 1u) | ((k & 0xAAAAAAAAu) >> 1u);
    k = ((k & 0x33333333u) << 2u) | ((k & 0xCCCCCCCCu) >> 2u);
    k = ((k & 0x0F0F0F0Fu) << 4u) | ((k & 0xF0F0F0F0u) >> 4u);
    k = ((k & 0x00FF00FFu) << 8u) | ((k & 0xFF00FF00u) >> 8u);
    return static_cast<double>(k) * 2.3283064365386963e-10;
}

PreparedLight prepareLight(const booth::BoothLight& light,
                           const colour::Observer& obs,
                           int pointLightCount,
                           const colour::ChannelBasis& basis)
{
    PreparedLight p;
    p.light = &light;
    const auto regions =
            booth::medianCut(light.luminance, booth::medianCutOptionsFor(light, pointLightCount));
    p.points = booth::pointLights(light, regions);
    p.mips = booth::buildMipChain(light.luminance);
    p.unitSpd = booth::unitLuminanceSpd(obs, light.spd);
    p.white = colour::spectrumToXyz(obs, p.unitSpd);
    p.channelXyz = colour::channelToXyz(basis, obs, light.spd);
    return p;
}

namespace {

// The palette's reflectances projected on the basis: what a basis change re-does.
std::vector<colour::ChannelCoeffs> paletteCoeffs(const surface::SurfaceScene& scene,
                                                 const colour::ChannelBasis& basis)
{
    std::vector<colour::ChannelCoeffs> c;
    for (const auto& s : scene.palette) {
        c.push_back(colour::projectReflectance(basis, s));
    }
    return c;
}

} // namespace

PreparedScene prepareScene(const surface::SurfaceScene& scene,
                           int horizonDirections,
                           double horizonDistanceM,
                           const colour::ChannelBasis& basis)
{
    PreparedScene p;
    p.scene = &scene;
    if (!scene.flat()) {
        p.normals = surface::normalMap(scene.relief);
        p.horizon = surface::horizonMap(scene.relief, horizonDirections, horizonDistanceM);
        p.horizonHalf = surface::halfPrecision(p.horizon);
    }
    p.paletteCoeffs = paletteCoeffs(scene, basis);
    return p;
}

PreparedScene reprojectScene(const PreparedScene& prepared,
                             const surface::SurfaceScene& scene,
                             const colour::ChannelBasis& basis)
{
    PreparedScene p;
    p.scene = &scene;
    p.normals = prepared.normals;
    p.horizon = prepared.horizon;
    p.horizonHalf = prepared.horizonHalf;
    p.paletteCoeffs = paletteCoeffs(scene, basis);
    return p;
}

double pointLightIrradiance(const std::vector<booth::PointLight>& lights,
                            const Vec3& lightNormal,
                            double texelAreaM2,
                            const ShadingPoint& sp,
                            const surface::HorizonMap* horizon,
                            double softness,
                            bool bilinear)
{
    const Vec3& p = sp.p;
    const Vec3& nGeo = sp.nGeo;
    const Vec3& nShade = sp.nShade;
    const ReliefLightVisibility vis(sp, horizon, bilinear, texelAreaM2, softness);
    double e = 0.0;
    for (const booth::PointLight& l : lights) {
        Vec3 d = l.position - p;
        const double d2 = glm::dot(d, d);
        if (!(d2 > 0.0) || !(l.sumCdM2 > 0.0)) {
            continue;
        }
        d /= std::sqrt(d2);
        const double cosL = -glm::dot(lightNormal, d);
        const double cosG = glm::dot(nGeo, d);
        const double cosS = glm::dot(nShade, d);
        if (!(cosL > 0.0) || !(cosG > 0.0) || !(cosS > 0.0)) {
            continue;
        }
        e += l.sumCdM2 * cosS * cosL / std::max(d2, texelAreaM2) * vis.along(l, d, d2, cosG);
    }
    return e * texelAreaM2;
}

int clipToHorizon(const Vec3* v, int count, const Vec3& n, Vec3* out)
{
    int m = 0;
    for (int i = 0; i < count; ++i) {
        const Vec3& a = v[i];
        const Vec3& b = v[(i + 1) % count];
        const double da = glm::dot(n, a);
        const double db = glm::dot(n, b);
        if (da >= 0.0) {
            out[m++] = a;
        }
        if ((da >= 0.0) != (db >= 0.0)) {
            // One end above, one below: da - db is nonzero and t in [0, 1].
            out[m++] = a + (b - a) * (da / (da - db));
        }
    }
    return m;
}

double edgeTerm(const Vec3& a, const Vec3& b, const Vec3& n)
{
    const Vec3 c = glm::cross(a, b);
    const double len = glm::length(c);
    if (!(len > 0.0)) {
        return 0.0;
    }
    return std::atan2(len, glm::dot(a, b)) * (glm::dot(n, c) / len);
}

double projectedSolidAngle(const Vec3* v, int count, const Vec3& n)
{
    double sum = 0.0;
    for (int i = 0; i < count; ++i) {
        sum += edgeTerm(v[i], v[(i + 1) % count], n);
    }
    return 0.5 * std::abs(sum);
}

double regionIrradiance(const booth::PointLight& region,
                        const Vec3& lightNormal,
                        const Vec3& p,
                        const Vec3& nGeo,
                        const Vec3& nShade)
{
    const Vec3 o = region.regionOrigin - p;
    // In front of the emitting side, by more than rounding of the region's size: in (or behind)
    // its plane the region lights nothing (and an edge could pass through p).
    const double scale = glm::length(region.regionU) + glm::length(region.regionV);
    if (!(region.meanCdM2 > 0.0) || !(-glm::dot(o, lightNormal) > 1e-12 * scale)) {
        return 0.0;
    }
    const std::array<Vec3, 4> quad{o, o + region.regionU, o + region.regionU + region.regionV,
                                   o + region.regionV};
    std::array<Vec3, kMaxClippedVertices> geo{};
    const int m = clipToHorizon(quad.data(), 4, nGeo, geo.data());
    if (m < 3) {
        return 0.0;
    }
    if (nShade == nGeo) {
        return region.meanCdM2 * projectedSolidAngle(geo.data(), m, nGeo);
    }
    std::array<Vec3, kMaxClippedVertices> shade{};
    const int k = clipToHorizon(geo.data(), m, nShade, shade.data());
    return k < 3 ? 0.0 : region.meanCdM2 * projectedSolidAngle(shade.data(), k, nShade);
}

double areaLightIrradiance(const std::vector<booth::PointLight>& lights,
                           const Vec3& lightNormal,
                           double texelAreaM2,
                           const ShadingPoint& sp,
                           const surface::HorizonMap* horizon,
                           double softness,
                           bool bilinear)
{
    const ReliefLightVisibility vis(sp, horizon, bilinear, texelAreaM2, softness);
    double e = 0.0;
    for (const booth::PointLight& l : lights) {
        const double er = regionIrradiance(l, lightNormal, sp.p, sp.nGeo, sp.nShade);
        if (!(er > 0.0)) {
            continue;
        }
        e += er * vis.towards(l, sp.p);
    }
    return e;
}

double panelWhiteY(const PreparedLight& light, const PanelPose& panel, bool areaLights)
{
    const booth::BoothLight& bl = *light.light;
    const ShadingPoint centre{panel.centre, panel.normal, panel.normal, panel.right, panel.up};
    const auto irradiance = areaLights ? areaLightIrradiance : pointLightIrradiance;
    return irradiance(light.points, bl.normal(), bl.texelAreaM2(), centre, nullptr, 0.0, false) /
           std::numbers::pi;
}

double filteredSpecular(const PreparedLight& light,
                        const ShadingPoint& sp,
                        const Vec3& toEye,
                        brdf::WardModel model,
                        double alpha,
                        int samples,
                        const surface::HorizonMap* horizon,
                        double softness,
                        double lodBias,
                        bool nearestLevel)
{
    const Vec3& p = sp.p;
    const Vec3& nGeo = sp.nGeo;
    const Vec3& nShade = sp.nShade;
    const booth::BoothLight& bl = *light.light;
    const Vec3 nl = bl.normal();
    const double a = bl.texelAreaM2();
    const double invU2 = 1.0 / glm::dot(bl.edgeU, bl.edgeU);
    const double invV2 = 1.0 / glm::dot(bl.edgeV, bl.edgeV);
    // One horizon sine for the whole lobe, read at the azimuth of the mirror direction; each
    // sample is tested against it at its own elevation. The lobe's samples share that azimuth
    // wherever the horizon can shadow them (near the horizon; near the normal the azimuth spreads
    // but the elevation clears any horizon), and the per-sample azimuth and horizon lookup were a
    // third of the painting's frame on llvmpipe (docs/rendering.md has the error it costs).
    double lobeSinB = 0.0;
    if (horizon != nullptr && horizon->directions > 0) {
        const Vec3 mirror = 2.0 * glm::dot(nShade, toEye) * nShade - toEye;
        lobeSinB = horizon->sinHorizon(
                sp.tx, sp.ty, Vec3(glm::dot(mirror, sp.right), glm::dot(mirror, sp.up), 0.0));
    }
    // The ceiling's plane and axes from p, once (the shader hoists them out of its loop too).
    const Vec3 pc = p - bl.centre;
    const double planeDist = -glm::dot(pc, nl);
    const Vec3 eu = bl.edgeU * invU2;
    const Vec3 ev = bl.edgeV * invV2;
    const double u0 = glm::dot(pc, eu) + 0.5;
    const double v0 = glm::dot(pc, ev) + 0.5;
    double sum = 0.0;
    for (int k = 0; k < samples; ++k) {
        const double u1 = (k + 0.5) / samples;
        const double u2 = radicalInverse2(static_cast<unsigned>(k));
        const brdf::WardSample s = brdf::sampleWard(model, alpha, nShade, toEye, u1, u2, samples);
        if (!s.valid) {
            continue;
        }
        const double cosG = glm::dot(nGeo, s.i);
        const double denom = glm::dot(s.i, nl);
        if (!(cosG > 0.0) || !(denom < 0.0)) {
            continue; // below the macro surface, or heading away from the emitting side
        }
        const double t = planeDist / denom;
        if (!(t > 0.0) || !std::isfinite(t)) {
            continue;
        }
        const double u = u0 + t * glm::dot(s.i, eu); // the hit p + t i, in the ceiling's axes
        const double v = v0 + t * glm::dot(s.i, ev);
        if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0)) {
            continue; // the dark booth
        }
        const double cosL = -denom;
        const double ratio = s.solidAngle * t * t / (a * cosL);
        const double lod = 0.5 * std::log2(std::max(ratio, 1e-20)) + lodBias;
        const double lum = nearestLevel ? light.mips.sampleNearestLevel(u, v, lod)
                                        : light.mips.sample(u, v, lod);
        sum += lum * s.weight * elevationVisibility(lobeSinB, cosG, softness);
    }
    return samples > 0 ? sum / samples : 0.0;
}

GridNodes gridNodes(const surface::SurfaceScene& scene, int spacingTexels)
{
    if (spacingTexels <= 0 || scene.width <= 0 || scene.height <= 0) {
        return {};
    }
    return {(scene.width + spacingTexels - 1) / spacingTexels + 1,
            (scene.height + spacingTexels - 1) / spacingTexels + 1};
}

namespace {

// The largest power of two g <= most whose g texels turn the surface by at most 'reach'
// radians, where it turns by 'turn' a texel at most; 0 when one texel already turns further.
// Compared as products, so that a plane's zero turn (a tilted plane is relief too) divides
// nothing: it gets 'most'.
int gridWithin(double turn, double reach, int most)
{
    int grid = 0;
    for (int g = 1; g <= most && turn * g <= reach; g *= 2) {
        grid = g;
    }
    return grid;
}

} // namespace

int defaultSpecularGrid(const surface::SurfaceScene& scene)
{
    if (scene.flat()) {
        return kFlatSpecularGrid;
    }
    // The mirror direction turns twice as fast as the normal.
    return gridWithin(surface::largestNormalTurn(scene.relief),
                      0.5 * kReliefGridLobeFraction * scene.alpha, kFlatSpecularGrid);
}

int defaultDiffuseGrid(const surface::SurfaceScene& scene)
{
    if (scene.flat()) {
        return kFlatDiffuseGrid;
    }
    return gridWithin(surface::largestNormalTurn(scene.relief),
                      kReliefDiffuseGridSoftnesses * RenderSettings{}.horizonSoftness,
                      kFlatDiffuseGrid);
}

bool defaultAreaLights(const surface::SurfaceScene& scene)
{
    return scene.flat();
}

int defaultSpecularSamples(const surface::SurfaceScene& scene)
{
    return scene.flat() ? kFlatSpecularSamples : kReliefSpecularSamples;
}

double gridValue(const std::vector<double>& values, GridNodes nodes, double u, double v)
{
    const double lastX = nodes.x - 1;
    const double lastY = nodes.y - 1;
    const double fx = std::clamp(u, 0.0, 1.0) * lastX;
    const double fy = std::clamp(v, 0.0, 1.0) * lastY;
    const double x0 = std::min(std::floor(fx), lastX - 1.0);
    const double y0 = std::min(std::floor(fy), lastY - 1.0);
    const double ax = fx - x0;
    const double ay = fy - y0;
    const auto at = [&](int x, int y) {
        return values[static_cast<std::size_t>(y) * static_cast<std::size_t>(nodes.x) +
                      static_cast<std::size_t>(x)];
    };
    const int ix = static_cast<int>(x0);
    const int iy = static_cast<int>(y0);
    return (1.0 - ay) * ((1.0 - ax) * at(ix, iy) + ax * at(ix + 1, iy)) +
           ay * ((1.0 - ax) * at(ix, iy + 1) + ax * at(ix + 1, iy + 1));
}

} // namespace replica::pipeline::shading
