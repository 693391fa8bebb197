// The real-time renderer's algorithm on the CPU: median-cut point lights (eq. 1) with normal-mapped
// facets and horizon shadows, Ward specular by filtered importance sampling of the mip-mapped
// luminance image, channel reflectance (eq. 2) and screen-flare subtraction. It is the executable
// specification the GLES shaders follow (float there, double here) and what the speed-vs-error
// sweep measures against the reference.
#pragma once

#include <vector>

#include <pipeline/booth/booth_light.h>
#include <pipeline/booth/luminance_image.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/shading/frame.h>
#include <pipeline/shading/view.h>
#include <pipeline/surface/scene.h>

namespace replica::pipeline::shading {

enum class ChannelRep {
    Basis6,     // K = 6 channel coefficients per texel, 6 XYZ vectors per light (the GL path), in
                // the basis the scene and light were prepared with
    Spectral36, // full spectra per texel (what the channels approximate)
};

struct RenderSettings {
    int lights = 32;
    int specularSamples = 48;
    int horizonDirections = 8;
    ChannelRep channels = ChannelRep::Basis6;
    bool diffusePass = true;
    bool specularPass = true;      // ignored (skipped) for a matte scene
    bool reliefPass = true;        // normal map + horizon; ignored for a flat scene
    double horizonSoftness = 0.02; // half-width of the smoothstep in sin(elevation)
    // Subtract the screen's front-surface flare here (the GL pass only: the CPU model always does).
    // The appliance turns it off when its display pass subtracts the flare instead, so that the
    // reflection is never subtracted twice.
    bool subtractFlare = true;
    int threads = 2;
};

// Per-light precomputation: median cut, mip chain, spectra. Rebuilt only when the light or N
// changes.
struct PreparedLight {
    const booth::BoothLight* light = nullptr;
    std::vector<booth::PointLight> points;
    booth::MipChain mips;
    colour::Spectrum unitSpd;
    colour::Xyz white{0.0};            // XYZ of the unit-luminance light (Y = 1)
    colour::ChannelToXyz channelXyz{}; // M_k for the Basis6 path
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
    std::vector<colour::ChannelCoeffs> paletteCoeffs;
};

PreparedScene prepareScene(const surface::SurfaceScene& scene,
                           int horizonDirections,
                           double horizonDistanceM = 0.01,
                           const colour::ChannelBasis& basis = colour::boxBasis());

// Diffuse illuminance from point lights (eq. 1): both cosines clamped at 0, 1/d^2 clamped at one
// texel area; vis(light direction) in [0, 1] multiplies each light.
double pointLightIrradiance(const std::vector<booth::PointLight>& lights,
                            const Vec3& lightNormal,
                            double texelAreaM2,
                            const Vec3& p,
                            const Vec3& nGeo,
                            const Vec3& nShade,
                            const surface::HorizonMap* horizon,
                            int tx,
                            int ty,
                            const Vec3& right,
                            const Vec3& up,
                            double softness);

// Specular radiance (cd/m^2, rho_s = 1) by FIS with N Hammersley samples (u1 = (k + 1/2) / N).
double filteredSpecular(const PreparedLight& light,
                        const Vec3& p,
                        const Vec3& nGeo,
                        const Vec3& nShade,
                        const Vec3& toEye,
                        brdf::WardModel model,
                        double alpha,
                        int samples,
                        const surface::HorizonMap* horizon,
                        int tx,
                        int ty,
                        const Vec3& right,
                        const Vec3& up,
                        double softness);

XyzFrame renderRealtime(const PreparedScene& scene,
                        const PreparedLight& light,
                        const View& view,
                        const colour::Observer& obs,
                        const RenderSettings& settings);

double radicalInverse2(unsigned k);

} // namespace replica::pipeline::shading
