// Booth light geometry and the mapping of median-cut regions onto the emitter.
#include <cmath>

#include <glm/geometric.hpp>

#include <pipeline/booth/booth_light.h>

namespace replica::pipeline::booth {

Vec3 BoothLight::normal() const
{
    return glm::normalize(glm::cross(edgeU, edgeV));
}

double BoothLight::areaM2() const
{
    return glm::length(glm::cross(edgeU, edgeV));
}

double BoothLight::texelAreaM2() const
{
    const double n = static_cast<double>(luminance.width) * static_cast<double>(luminance.height);
    return n > 0.0 ? areaM2() / n : 0.0;
}

double BoothLight::texelWidthM() const
{
    return luminance.width > 0 ? glm::length(edgeU) / luminance.width : 0.0;
}

double BoothLight::texelHeightM() const
{
    return luminance.height > 0 ? glm::length(edgeV) / luminance.height : 0.0;
}

Vec3 BoothLight::pointAtTexel(double x, double y) const
{
    return centre + edgeU * (x / luminance.width - 0.5) + edgeV * (y / luminance.height - 0.5);
}

colour::Spectrum unitLuminanceSpd(const colour::Observer& obs, const colour::Spectrum& spd)
{
    const double y = colour::spectrumToXyz(obs, spd).y;
    if (!(y > 0.0)) {
        return colour::Spectrum{};
    }
    return spd * (1.0 / y);
}

std::vector<PointLight> pointLights(const BoothLight& light,
                                    const std::vector<RegionLight>& regions)
{
    std::vector<PointLight> out;
    out.reserve(regions.size());
    const LuminanceImage& img = light.luminance;
    const Vec3 uHat = glm::normalize(light.edgeU);
    const Vec3 vHat = glm::normalize(light.edgeV);
    for (const RegionLight& r : regions) {
        // Second moments about the centroid, each texel a uniform square (its own spread 1/12).
        double sum = 0.0, sxx = 0.0, syy = 0.0;
        for (int y = r.y0; y < r.y1; ++y) {
            for (int x = r.x0; x < r.x1; ++x) {
                const double l = img.at(x, y);
                const double dx = x + 0.5 - r.centroidX;
                const double dy = y + 0.5 - r.centroidY;
                sum += l;
                sxx += l * (dx * dx + 1.0 / 12.0);
                syy += l * (dy * dy + 1.0 / 12.0);
            }
        }
        PointLight p;
        p.position = light.pointAtTexel(r.centroidX, r.centroidY);
        p.intensityCd = r.sumCdM2 * light.texelAreaM2();
        p.sumCdM2 = r.sumCdM2;
        if (sum > 0.0) {
            p.spreadU = uHat * (std::sqrt(sxx / sum) * light.texelWidthM());
            p.spreadV = vHat * (std::sqrt(syy / sum) * light.texelHeightM());
        }
        // The uniform rectangle with the region's power, centroid and spread: centred on the
        // centroid, sqrt(12) standard deviations wide along each edge (a uniform box of width w
        // has w / sqrt(12)). A uniform region is its own rectangle exactly; a tube in a dim region
        // becomes a narrower, brighter rectangle than the region's (whose spread would be too
        // wide): what is left is in the light's moments past the second, where a point light's
        // error starts at the second.
        const double hu = std::sqrt(3.0) * glm::length(p.spreadU);
        const double hv = std::sqrt(3.0) * glm::length(p.spreadV);
        p.regionOrigin = p.position - uHat * hu - vHat * hv;
        p.regionU = uHat * (2.0 * hu);
        p.regionV = vHat * (2.0 * hv);
        const double area = 4.0 * hu * hv;
        p.meanCdM2 = area > 0.0 ? r.sumCdM2 * light.texelAreaM2() / area : 0.0;
        out.push_back(p);
    }
    return out;
}

MedianCutOptions medianCutOptionsFor(const BoothLight& light, int count)
{
    MedianCutOptions o;
    o.count = count;
    o.texelWidthM = light.texelWidthM();
    o.texelHeightM = light.texelHeightM();
    return o;
}

} // namespace replica::pipeline::booth
