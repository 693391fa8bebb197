// CIE 1931 tristimulus integration on the working grid.
#include <pipeline/colour/spectral_table.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::colour {

Expected<Observer> loadCie1931(const std::filesystem::path& dataDir)
{
    auto table = loadSpectralCsv(dataDir / "spectra" / "cie1931_2deg_cmf_10nm_380_730.csv");
    if (!table) {
        return tl::unexpected(table.error());
    }
    Observer obs;
    // The 10 nm table is on the working grid already; a colour-matching function, like a
    // reflectance, is sampled at the band centres, never averaged over them.
    auto x = table->spectrum("xbar", GridSampling::AtBandCentre);
    auto y = table->spectrum("ybar", GridSampling::AtBandCentre);
    auto z = table->spectrum("zbar", GridSampling::AtBandCentre);
    if (!x || !y || !z) {
        return tl::unexpected(!x ? x.error() : (!y ? y.error() : z.error()));
    }
    obs.xbar = *x;
    obs.ybar = *y;
    obs.zbar = *z;
    return obs;
}

Xyz spectrumToXyz(const Observer& obs, const Spectrum& s)
{
    Xyz xyz{0.0};
    for (std::size_t i = 0; i < kBands; ++i) {
        xyz.x += s[i] * obs.xbar[i];
        xyz.y += s[i] * obs.ybar[i];
        xyz.z += s[i] * obs.zbar[i];
    }
    return xyz * kStepNm;
}

Xyz reflectanceToXyz(const Observer& obs, const Spectrum& light, const Spectrum& reflectance)
{
    const Xyz white = spectrumToXyz(obs, light);
    if (!(white.y > 0.0)) {
        return Xyz{0.0};
    }
    return spectrumToXyz(obs, light * reflectance) * (100.0 / white.y);
}

} // namespace replica::pipeline::colour
