// The real-time renderer's algorithm on the CPU: median-cut point lights (eq. 1) with normal-mapped
// facets and horizon shadows, Ward specular by filtered importance sampling of the mip-mapped
// luminance image, channel reflectance (eq. 2) and screen-flare subtraction. It is the executable
// specification the GLES shaders follow (float there, double here) and what the speed-vs-error
// sweep measures against the reference.
#pragma once

#include <optional>
#include <vector>

#include <glm/vec2.hpp>

#include <pipeline/booth/booth_light.h>
#include <pipeline/booth/booth_walls.h>
#include <pipeline/booth/luminance_image.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/shading/frame.h>
#include <pipeline/shading/view.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::shading {

enum class ChannelRep {
    Basis6,     // K = 6 channel coefficients per texel, 6 XYZ vectors per light (the GL path), in
                // the basis the scene and light were prepared with
    Spectral36, // full spectra per texel (what the channels approximate)
};

// The specular mip level bias the renderer uses unless told otherwise (RenderSettings).
inline constexpr double kDefaultSpecularLodBias = 0.0;
// The largest |bias| a command line or a recorded configuration may ask for (8 levels: a 256x
// sharper or blurrier footprint, far past any useful setting).
inline constexpr double kMaxSpecularLodBias = 8.0;

// Specular samples per pixel (or per grid node) the appliance and 'replica render' use unless
// told. Relief is shaded per pixel, so each sample costs the whole surface a texture read (about
// 1.4 ms of the painting's 960x600 frame on 2-core llvmpipe) and 8 of them meet the budget there
// (worst light p95 / max 0.63 / 2.09 on the 128x80 error frame); a flat surface is shaded at the
// grid's nodes, where samples cost next to nothing (12 -> 24: about 1 ms of the ColorChecker's
// frame) and the ColorChecker needs 24: over nine views (three eyes, tilts 10 to 50 degrees;
// replica_bench_render --views) 12 reach p95 1.09 and 16 reach 1.29 under d50 at a 50-degree
// tilt, where the tubes' reflection aliases against the sample pattern; 24 keep every view
// within p95 0.72, max 1.00. docs/rendering.md has the sweeps.
constexpr int kReliefSpecularSamples = 8;
constexpr int kFlatSpecularSamples = 24;

struct RenderSettings {
    int lights = 32;
    // kFlatSpecularSamples (above). The appliance and 'replica render' take
    // defaultSpecularSamples for the scene instead.
    int specularSamples = kFlatSpecularSamples;
    int horizonDirections = 8;
    ChannelRep channels = ChannelRep::Basis6;
    bool diffusePass = true;
    bool specularPass = true;      // ignored (skipped) for a matte scene
    bool reliefPass = true;        // normal map + horizon; ignored for a flat scene
    double horizonSoftness = 0.02; // half-width of the smoothstep in sin(elevation)
    // The diffuse term (eq. 1) from areas, not points: each median-cut region is the uniform
    // rectangle it covers on the ceiling (its mean luminance), its irradiance Lambert's contour
    // integral over the region clipped to the surface's horizon (areaLightIrradiance). Point
    // lights are wrong in the near field: the shipped 1.0 x 0.5 m ceiling cut into 32 regions of
    // 12.5 cm half a metre away lit a flat matte surface 2-3 % too bright at small tilts. Relief
    // keeps one horizon test per region, at its centroid's direction. Off: point lights (the
    // appliance's choice on relief, defaultAreaLights).
    bool areaLights = true;
    // The GL pass only, and only across frames (one frame is the same either way): when the
    // panel's pose changes, the cached eye-independent part (eq. 1 and 2, the frame's costly part
    // on relief) is recomputed in this many bands of rows over as many frames, into a second
    // cache, while the frames go on composing from the last complete one
    // (render::BoothShadingPass::draw). A tilting frame then pays a band instead of the whole,
    // and the diffuse term lags the tilt by a few frames while it moves; once the panel stops,
    // the frames are those of 1 (recompute whole at once), bit for bit. 1 for a one-off render;
    // the appliance sets its own (platform::RunConfig::cacheSlices).
    int cacheSlices = 1;
    // The GL pass only, and only across frames: above 0, the cached diffuse term is drawn at tilt
    // nodes this far apart (radians) and a frame interpolates the two that bracket its tilt
    // (scene::nextDiffuseNodes); the cache then holds up to kMaxDiffuseNodes terms and a
    // refresh's, and a frame whose tilt lies between two nodes one interpolated term more.
    // 0: the held tilt's term alone (a one-off render; recordings made before tilt nodes).
    double tiltNodesRad = 0.0;
    // Subtract the screen's front-surface flare here (the GL pass only: the CPU model always does).
    // The appliance turns it off when its display pass subtracts the flare instead, so that the
    // reflection is never subtracted twice.
    bool subtractFlare = true;
    // Texels between the nodes of the specular grid; 0: the specular term per pixel. The
    // specular term follows the eye, so it is shaded every frame; on a flat surface it varies
    // smoothly over the surface, and shading it at grid nodes and interpolating costs a fraction
    // of shading it per pixel (gridNodes; the planner measures the error it adds).
    int specularGrid = 0;
    // Texels between the nodes of the diffuse grid; 0: eq. (1) per pixel. On relief the nodes
    // hold eq. (1) with their own facets and horizons as well (defaultDiffuseGrid says where that
    // holds: where the relief turns slowly). On a flat surface the illuminance from
    // the booth's lights varies over centimetres, not texels: summed at the grid's nodes
    // (gridNodes' layout) and interpolated, it costs a frame that recomputes the cache
    // (the panel being tilted) a few hundred sums instead of one per pixel.
    int diffuseGrid = 0;
    // Added to each specular sample's mip level (Colbert & Krivanek's level, 1/2 log2 of the
    // sample's footprint over a texel's): more blurs the luminance image under each sample, less
    // aliases it. Colbert & Krivanek add 1; docs/rendering.md measures 0 as the better choice
    // against the exact reference at every sample count the appliance uses.
    double specularLodBias = kDefaultSpecularLodBias;
    // Read each specular sample from the one mip level nearest its own (MipChain::
    // sampleNearestLevel) instead of between the two around it: half the texel fetches, about
    // 15% of the painting's frame on llvmpipe, for p95 0.57 / max 1.64 at worst against 0.52 /
    // 1.13 (docs/rendering.md). The CPU model takes either (the studies compare them); the GL
    // pass renders the nearest level only, at a bias of whole half levels (BoothShadingPass
    // refuses other settings).
    bool specularNearestLevel = true;
    int threads = 2;
    // Light the surface from the booth's walls too, where the light carries them
    // (PreparedLight::walls): their light on the panel is baked into a WallField whenever the
    // panel moves (shading/wall_field.h) and added to eq. (1), the flare and the white. Off (the
    // default) costs nothing and leaves every frame as it was.
    bool walls = false;
};

// Nodes of a grid (specular or diffuse) for a spacing in texels: (ceil(width / s) + 1) x
// (ceil(height / s) + 1), spread evenly over the surface with its corners included, node (i, j) at
// (u, v) = (i / (x - 1), j / (y - 1)). {0, 0} for s <= 0 (per pixel).
struct GridNodes {
    int x = 0;
    int y = 0;
};
GridNodes gridNodes(const surface::SurfaceScene& scene, int spacingTexels);

// On a flat surface the specular term varies smoothly: shaded every 8 texels and interpolated,
// the shipped ColorChecker stays inside the ΔE00 budget (p95 0.67 / max 0.86 against 0.66 / 0.89
// per pixel, docs/rendering.md) for about a sixtieth of the specular cost. On relief it depends on
// how fast the surface turns: the painting's highlights on the weave and the strokes are
// texel-sized (its max reaches 5.6 at 1 texel), the glossy cylinder's turn a third of a degree a
// texel and vary as smoothly as its lobe.
constexpr int kFlatSpecularGrid = 8;
// Relief: the mirror direction turns by twice the normal's turn, so across g texels by
// 2 g largestNormalTurn. The grid is the largest power of two (at most kFlatSpecularGrid) over
// which that stays within this fraction of the lobe's width (the Ward alpha, radians), and per
// pixel (0) when even one texel is too far. Measured on the glossy cylinder (alpha 0.05, 0.45
// degrees a texel at its edges: a grid of 2) at the appliance's 1.85 pixels a texel, against the
// exact reference: ΔE00 p95 0.31 per pixel, 0.33 at 1 texel, 0.40 at 2, 0.9 at 4
// (docs/rendering.md, "Specular grid").
constexpr double kReliefGridLobeFraction = 0.75;
// The spacing the appliance and 'replica render' use unless told: kFlatSpecularGrid on a flat
// surface, the rule above on relief.
int defaultSpecularGrid(const surface::SurfaceScene& scene);

// On a flat surface the diffuse term (eq. 1 with the macro normal) is summed every 8 texels and
// interpolated: the shipped flat scenes move by ΔE00 0.01 at most against per pixel (docs/
// rendering.md).
constexpr int kFlatDiffuseGrid = 8;
// Relief: eq. (1) with each node's facet and horizons. Its cosines are wide; what varies fastest
// is each light's horizon test, a smoothstep 2 horizonSoftness wide in the sine of the light's
// elevation, which the horizon sweeps about as fast as the surface turns. The grid is the largest
// power of two (at most kFlatDiffuseGrid) whose span turns the surface by at most this many
// softnesses, and per pixel where one texel turns further (the painting). Measured on the glossy
// cylinder (0.45 degrees a texel: a grid of 4) under D65 with its plan's 128 lights at the
// appliance's density, against per pixel: p95 0.005 / max 0.10 at tilt 30, 0.042 / 0.29 at tilt
// 10 from the side; at 8 texels 0.061 / 0.13 and 0.125 / 0.37 (docs/rendering.md).
constexpr double kReliefDiffuseGridSoftnesses = 2.0;
// The spacing the appliance and 'replica render' use unless told: kFlatDiffuseGrid on a flat
// surface, the rule above on relief.
int defaultDiffuseGrid(const surface::SurfaceScene& scene);

// Whether the appliance lights eq. (1) from areas unless told (RenderSettings::areaLights): on a
// flat surface, where the diffuse grid sums it at a few hundred nodes and areas cost next to
// nothing; not on relief, where it is summed per pixel and areas made the painting's whole
// recompute 3.1x as long on llvmpipe (53 -> 165 ms, docs/performance.md) while point lights keep
// it within the budget (docs/rendering.md). 'replica render' uses areas everywhere.
bool defaultAreaLights(const surface::SurfaceScene& scene);

// The specular sample count the appliance and 'replica render' use unless told
// (kReliefSpecularSamples or kFlatSpecularSamples).
int defaultSpecularSamples(const surface::SurfaceScene& scene);

// A grid's value at (u, v): bilinear between the four nodes around it (values row by row, nodes.x
// per row); the specular grid's term and the diffuse grid's illuminance alike.
double gridValue(const std::vector<double>& values, GridNodes nodes, double u, double v);

// Per-light precomputation: median cut, mip chain, spectra. Rebuilt only when the light or N
// changes.
struct PreparedLight {
    const booth::BoothLight* light = nullptr;
    std::vector<booth::PointLight> points;
    booth::MipChain mips;
    colour::Spectrum unitSpd;
    colour::Xyz white{0.0};            // XYZ of the unit-luminance light (Y = 1)
    colour::ChannelToXyz channelXyz{}; // M_k for the Basis6 path
    // The booth's walls lit by this light (solved once at start-up, reference::solveWalls), or
    // none; used where RenderSettings::walls says. Not owned.
    const booth::WallLight* walls = nullptr;
};

// 'basis' must be the one the scene was prepared with (box6 when not given).
PreparedLight prepareLight(const booth::BoothLight& light,
                           const colour::Observer& obs,
                           int pointLightCount,
                           const colour::ChannelBasis& basis = colour::boxBasis());

// Per-scene precomputation: normal and horizon maps, palette channel coefficients.
struct PreparedScene {
    const surface::SurfaceScene* scene = nullptr;
    std::vector<Vec3> normals; // empty when flat
    surface::HorizonMap horizon;
    // surface::halfPrecision(horizon), rounded once here: what eq. (1) and the lobe read, as the
    // GL pass packs its horizons as half floats (the
    // planner renders one prepared scene dozens of times). Whoever replaces 'horizon' rounds it
    // again.
    surface::HorizonMap horizonHalf;
    std::vector<colour::ChannelCoeffs> paletteCoeffs;
};

PreparedScene prepareScene(const surface::SurfaceScene& scene,
                           int horizonDirections,
                           double horizonDistanceM = 0.01,
                           const colour::ChannelBasis& basis = colour::boxBasis());

// 'prepared' (made by prepareScene from a scene with the same content as 'scene') for 'scene' in
// another basis: the relief's normals and horizons, the costly part and the same in every basis
// (the painting's: about 0.4 s on the 2-core machine), copied; the palette projected anew.
PreparedScene reprojectScene(const PreparedScene& prepared,
                             const surface::SurfaceScene& scene,
                             const colour::ChannelBasis& basis);

// Diffuse illuminance from point lights (eq. 1) at the shading point sp (its position p, macro
// normal nGeo and facet normal nShade): both cosines clamped at 0, 1/d^2 clamped at one texel
// area; vis(light direction) in [0, 1] multiplies each light: a smoothstep across the relief's
// horizon whose half-width is 'softness' or sqrt(3) times the spread of the light's elevation sine
// over its ceiling region (booth::PointLight::spreadU/V), whichever is wider. The horizon (none
// when null) is the texel (sp.tx, sp.ty)'s, or with 'bilinear' the bilinear one at (sp.texX,
// sp.texY) (what renderRealtime asks on relief), its azimuths in sp's frame (right, up).
double pointLightIrradiance(const std::vector<booth::PointLight>& lights,
                            const Vec3& lightNormal,
                            double texelAreaM2,
                            const ShadingPoint& sp,
                            const surface::HorizonMap* horizon = nullptr,
                            double softness = 0.0,
                            bool bilinear = false);

// The area-light diffuse term (RenderSettings::areaLights), one function per equation. Vertices
// are vectors from the shading point to the polygon's corners, in order.

// The most vertices a rectangle clipped by two planes can have.
inline constexpr int kMaxClippedVertices = 6;

// Sutherland-Hodgman against the horizon of a surface with normal n at the shading point: the part
// of the convex polygon v[0, count) with n . v >= 0, into out (kMaxClippedVertices room for a
// quadrilateral clipped twice). Returns its vertex count, 0 when all of it is below.
int clipToHorizon(const Vec3* v, int count, const Vec3& n, Vec3* out);

// One edge's term of Lambert's contour integral: the angle the edge a -> b subtends at the point
// times n . normalize(a x b). The angle is atan2(|a x b|, a . b), the acos of the unit vectors'
// dot product without its loss of precision near 0 and pi; 0 for an edge of zero length or one in
// line with the point (a x b = 0).
double edgeTerm(const Vec3& a, const Vec3& b, const Vec3& n);

// Lambert's formula: the projected solid angle (sr; pi for the whole hemisphere) of a planar
// polygon above the horizon of n, 1/2 |sum of its edges' terms|.
double projectedSolidAngle(const Vec3* v, int count, const Vec3& n);

// The irradiance (lux) at p from one median-cut region taken as the uniform rectangle it covers
// (booth::PointLight::regionOrigin/U/V, meanCdM2): L times the projected solid angle, for the
// facet normal nShade, of the region clipped to the macro surface's horizon (nGeo) and to the
// facet's (nShade; skipped when it is nGeo). 0 when p is not in front of the emitting side.
double regionIrradiance(const booth::PointLight& region,
                        const Vec3& lightNormal,
                        const Vec3& p,
                        const Vec3& nGeo,
                        const Vec3& nShade);

// Eq. (1) from areas: regionIrradiance summed over the regions, each times the relief's
// horizonVisibility evaluated once, along the direction of the region's centroid (the point
// light's position) with pointLightIrradiance's softness. Same arguments as pointLightIrradiance
// (texelAreaM2 only floors the softness's distance).
double areaLightIrradiance(const std::vector<booth::PointLight>& lights,
                           const Vec3& lightNormal,
                           double texelAreaM2,
                           const ShadingPoint& sp,
                           const surface::HorizonMap* horizon = nullptr,
                           double softness = 0.0,
                           bool bilinear = false);

// Y of a perfect white diffuser at the panel's centre under the light (XyzFrame::whiteY): eq. (1)
// from areas or from points as the settings say.
double panelWhiteY(const PreparedLight& light, const PanelPose& panel, bool areaLights);

// Specular radiance (cd/m^2, rho_s = 1) at sp, seen along toEye, by FIS with N Hammersley samples
// (u1 = (k + 1/2) / N). The horizon (none when null) shadows the lobe with one sine, read at the
// texel (sp.tx, sp.ty) at the mirror direction's azimuth; each sample is tested against it at its
// own elevation.
double filteredSpecular(const PreparedLight& light,
                        const ShadingPoint& sp,
                        const Vec3& toEye,
                        brdf::WardModel model,
                        double alpha,
                        int samples,
                        const surface::HorizonMap* horizon,
                        double softness,
                        double lodBias,
                        bool nearestLevel);

XyzFrame renderRealtime(const PreparedScene& scene,
                        const PreparedLight& light,
                        const View& view,
                        const colour::Observer& obs,
                        const RenderSettings& settings);

double radicalInverse2(unsigned k);

} // namespace replica::pipeline::shading
