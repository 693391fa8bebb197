// Synthetic luminance images: lamp hot spots behind a diffuser, fluorescent tube stripes, edge
// fall-off.
#include <cmath>
#include <numbers>

#include <pipeline/booth/lamp_kinds.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/offline/booth/booth_generator.h>

namespace replica::pipeline::booth {
namespace {

// Fall-off towards the diffuser's edges (less lamp area in view, shadowing by the housing).
double edgeFalloff(double u, double v)
{
    const auto ramp = [](double t) {
        const double d = std::min(t, 1.0 - t); // distance to the nearest edge, in units of the side
        return 0.55 + 0.45 * std::min(d / 0.18, 1.0);
    };
    return ramp(u) * ramp(v);
}

LuminanceImage tungstenImage(const CeilingGeometry& g)
{
    // Four incandescent lamps 3 cm behind the diffuser: each adds a Lorentzian-like hot spot.
    LuminanceImage img = LuminanceImage::filled(g.texelsX, g.texelsZ, 0.0);
    const double lamps[4][2] = {{0.2, 0.35}, {0.4, 0.65}, {0.6, 0.35}, {0.8, 0.65}};
    for (int y = 0; y < g.texelsZ; ++y) {
        for (int x = 0; x < g.texelsX; ++x) {
            const double u = (x + 0.5) / g.texelsX;
            const double v = (y + 0.5) / g.texelsZ;
            double l = 350.0;
            for (const auto& c : lamps) {
                const double dx = (u - c[0]) * g.widthM;
                const double dz = (v - c[1]) * g.depthM;
                const double r2 = (dx * dx + dz * dz) / (0.06 * 0.06);
                l += 2600.0 / std::pow(1.0 + r2, 1.5);
            }
            img.at(x, y) = l * edgeFalloff(u, v);
        }
    }
    return img;
}

LuminanceImage tubeImage(const CeilingGeometry& g,
                         const std::vector<double>& tubeV,
                         double base,
                         double peak,
                         double ripple)
{
    // Tubes run along x; each is a bright core with a diffuser-blurred skirt, dimmer at the tube
    // ends, plus a slight periodic ripple from the diffuser's prism pattern.
    LuminanceImage img = LuminanceImage::filled(g.texelsX, g.texelsZ, 0.0);
    for (int y = 0; y < g.texelsZ; ++y) {
        for (int x = 0; x < g.texelsX; ++x) {
            const double u = (x + 0.5) / g.texelsX;
            const double v = (y + 0.5) / g.texelsZ;
            double l = base;
            const double endFade = std::min(1.0, std::min(u, 1.0 - u) / 0.08);
            for (double c : tubeV) {
                const double dz = (v - c) * g.depthM / 0.012; // 1.2 cm core scale
                l += peak * endFade *
                     (std::exp(-0.5 * dz * dz) + 0.25 * std::exp(-0.5 * dz * dz / 9.0));
            }
            l *= 1.0 + ripple * std::sin(2.0 * std::numbers::pi * u * g.widthM / 0.02);
            img.at(x, y) = l * edgeFalloff(u, v);
        }
    }
    return img;
}

} // namespace

Expected<Booth> generateShippedBooth(const std::filesystem::path& dataDir, const CeilingGeometry& g)
{
    auto table = colour::loadSpectralCsv(dataDir / "spectra" /
                                         "cie_illuminants_10nm_380_730_triangular.csv");
    if (!table) {
        return tl::unexpected(table.error());
    }
    Booth booth;
    // One light per lamp kind, named and as bright as scene::loadDefaultBooth says the lamp is.
    for (const LampKind& s : kLampKinds) {
        auto spd = table->spectrum(s.column, colour::GridSampling::BandAverage);
        if (!spd) {
            return tl::unexpected(spd.error());
        }
        BoothLight l;
        l.name = s.name;
        l.centre = g.centre;
        l.edgeU = {g.widthM, 0.0, 0.0};
        l.edgeV = {0.0, 0.0, g.depthM}; // cross(u, v) = -y: emits down into the booth
        l.spd = *spd;
        if (l.name == "tungsten") {
            l.luminance = tungstenImage(g);
        } else if (l.name == "d50-fluorescent") {
            l.luminance = tubeImage(g, {0.2, 0.4, 0.6, 0.8}, 500.0, 2600.0, 0.03);
        } else {
            l.luminance = tubeImage(g, {0.25, 0.5, 0.75}, 650.0, 3200.0, 0.04);
        }
        const double mean = l.luminance.sum() / static_cast<double>(l.luminance.cdM2.size());
        for (double& v : l.luminance.cdM2) {
            v *= s.nominalLuminanceCdM2 / mean;
        }
        booth.lights.push_back(std::move(l));
    }
    return booth;
}

} // namespace replica::pipeline::booth
