// Training lights and sample weights for the channel fits.
#include <cmath>

#include <pipeline/colour/cat02.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/spectral/fit_metric.h>

namespace replica::pipeline::spectral {

using colour::kBands;

std::vector<FitLight>
makeFitLights(const Observer& obs, const Spectrum& d65, const NamedSpectra& lights, bool perceptual)
{
    const Xyz d65Xyz = colour::spectrumToXyz(obs, d65);
    const Xyz white = d65Xyz * (1.0 / d65Xyz.y);
    std::vector<FitLight> out;
    for (const Spectrum& e : lights.spectra) {
        const Xyz exyz = colour::spectrumToXyz(obs, e);
        if (!(exyz.y > 0.0)) {
            continue;
        }
        FitLight f;
        f.spectrum = e * (1.0 / exyz.y);
        f.a = DenseMatrix(3, kBands);
        for (std::size_t l = 0; l < kBands; ++l) {
            f.a(0, l) = obs.xbar[l] * f.spectrum[l] * colour::kStepNm;
            f.a(1, l) = obs.ybar[l] * f.spectrum[l] * colour::kStepNm;
            f.a(2, l) = obs.zbar[l] * f.spectrum[l] * colour::kStepNm;
        }
        f.h = DenseMatrix::identity(3);
        if (perceptual) {
            const colour::Matrix3 cat =
                    colour::cat02AdaptationMatrix(exyz * (1.0 / exyz.y), white, 1.0);
            DenseMatrix scaled(3, 3);
            const double inv[3] = {1.0 / white.x, 1.0 / white.y, 1.0 / white.z};
            for (std::size_t i = 0; i < 3; ++i) {
                for (std::size_t j = 0; j < 3; ++j) {
                    scaled(i, j) = inv[i] * cat[i][j];
                }
            }
            DenseMatrix jac(3, 3);
            jac(0, 1) = 116.0 / 3.0;
            jac(1, 0) = 500.0 / 3.0;
            jac(1, 1) = -500.0 / 3.0;
            jac(2, 1) = 200.0 / 3.0;
            jac(2, 2) = -200.0 / 3.0;
            f.h = jac * scaled;
        }
        out.push_back(std::move(f));
    }
    return out;
}

std::vector<double>
sampleWeights(const Observer& obs, const NamedSpectra& reflectances, bool perceptual)
{
    std::vector<double> w(reflectances.size(), 1.0);
    if (!perceptual) {
        return w;
    }
    auto slope = [](double y) {
        return y > colour::kLabEpsilon ? std::pow(y, -2.0 / 3.0) / 3.0 : colour::kLabKappa / 116.0;
    };
    const Spectrum equal = Spectrum::constant(1.0);
    for (std::size_t i = 0; i < reflectances.size(); ++i) {
        const double y = colour::reflectanceToXyz(obs, equal, reflectances.spectra[i]).y / 100.0;
        w[i] = slope(std::max(y, 0.0)) / slope(0.2);
    }
    return w;
}

DenseMatrix weightedSecondMoment(const NamedSpectra& reflectances,
                                 const std::vector<double>& weights)
{
    DenseMatrix c(kBands, kBands);
    const double n = static_cast<double>(std::max<std::size_t>(reflectances.size(), 1));
    for (std::size_t i = 0; i < reflectances.size(); ++i) {
        const double w2 = weights[i] * weights[i] / n;
        const Spectrum& r = reflectances.spectra[i];
        for (std::size_t a = 0; a < kBands; ++a) {
            for (std::size_t b = 0; b < kBands; ++b) {
                c(a, b) += w2 * r[a] * r[b];
            }
        }
    }
    return c;
}

} // namespace replica::pipeline::spectral
