// A booth light: a planar emitter with size and pose, a luminance image (cd/m^2) and an SPD.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/booth/luminance_image.h>
#include <pipeline/booth/median_cut.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::booth {

using Vec3 = glm::dvec3;

// Booth frame: right-handed, metres, y up. The emitter is the rectangle centre + s*edgeU + t*edgeV,
// s, t in [-1/2, 1/2]; image x runs along edgeU, image y along edgeV; the emitting side is
// normalize(cross(edgeU, edgeV)) (pointing down into the booth for a ceiling light).
struct BoothLight {
    std::string name;
    Vec3 centre{0.0};
    Vec3 edgeU{1.0, 0.0, 0.0};
    Vec3 edgeV{0.0, 0.0, 1.0};
    LuminanceImage luminance;
    colour::Spectrum spd; // relative spectral power; the luminance image carries the absolute scale
    // The lamp as the appliance knows it (filled by scene::loadDefaultBooth from its table of
    // lamps, by name; empty and zero in a booth read by loadBooth alone, as booth.json does not
    // hold them):
    // - referenceSpectrum: the lamp kind's CIE reference SPD (A, F8, F7) on the working grid,
    //   relative: what the light classifier matches a sensed spectrum against and the illuminant
    //   a frame is shaded under once the lamp is known. It differs in value from 'spd' (the
    //   booth model's own SPD, which the booth renderer's lights carry), so both stay.
    // - referenceFile / referenceColumn: where it comes from (data/spectra/<file>, column), at the
    //   table's own resolution for the simulated spectrometer.
    // - nominalLuminanceCdM2: the emitter's mean luminance with this lamp on, as the state's
    //   emitter luminance (the booth renderer's unknown light).
    colour::Spectrum referenceSpectrum{};
    std::string referenceFile;
    std::string referenceColumn;
    double nominalLuminanceCdM2 = 0.0;

    Vec3 normal() const;
    double areaM2() const;
    double texelAreaM2() const; // A/P in eq. (1)
    double texelWidthM() const;
    double texelHeightM() const;
    // Point on the emitter at texel coordinates (x, y) (texel x spans [x, x+1]).
    Vec3 pointAtTexel(double x, double y) const;
};

// The SPD scaled so that sum(spd * ybar) * 10 nm = 1: luminance L (cd/m^2) times this is the
// spectral radiance whose CIE Y is L. Zero spectrum if the light has no luminous power.
colour::Spectrum unitLuminanceSpd(const colour::Observer& obs, const colour::Spectrum& spd);

// A point light standing for part of an emitter (paper eq. 1): its intensity (cd) normal to the
// emitter's plane, used with the two cosines and 1/d^2: one median-cut region of a booth light's
// luminance image (pointLights).
struct PointLight {
    Vec3 position{0.0};
    double intensityCd = 0.0; // L * a: the summed luminance of the region times one texel's area
    // The summed luminance of the region's texels, eq. (1)'s L_n: the intensity is sumCdM2 times
    // the texel area.
    double sumCdM2 = 0.0;
    // The region's luminance-weighted standard deviation about 'position' along edgeU and edgeV,
    // as vectors in metres: how far the light the point stands for spreads over the ceiling.
    Vec3 spreadU{0.0};
    Vec3 spreadV{0.0};
    // The uniform rectangle that stands for the region in the area-light diffuse term
    // (shading::regionIrradiance): centred on 'position', sqrt(12) spreads wide along each edge,
    // so that its power, centroid and spread are the region's (a uniform region's is the region
    // itself): regionOrigin + s regionU + t regionV for s, t in [0, 1] (regionU along edgeU,
    // regionV along edgeV, so cross(regionU, regionV) is the emitting side), of luminance
    // meanCdM2 = sumCdM2 * texel area / its area (cd/m^2). Zero-sized for a dark region.
    Vec3 regionOrigin{0.0};
    Vec3 regionU{0.0};
    Vec3 regionV{0.0};
    double meanCdM2 = 0.0;
};

std::vector<PointLight> pointLights(const BoothLight& light,
                                    const std::vector<RegionLight>& regions);

MedianCutOptions medianCutOptionsFor(const BoothLight& light, int count);

} // namespace replica::pipeline::booth
