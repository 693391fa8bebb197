// Direct-sensor mode's level from a metered lamp (direct_level.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include <pipeline/spectral/direct_level.h>
#include <pipeline/spectral/light_classifier.h>

namespace replica::pipeline::spectral {

Expected<DirectLevelCalibration> calibrateDirectLevel(std::span<const RawSpectrum> spectra,
                                                      const SpectrometerCalibration& cal,
                                                      const InstrumentCalibration& instrument,
                                                      const colour::Observer& observer,
                                                      double luminanceCdM2)
{
    if (!std::isfinite(luminanceCdM2) || !(luminanceCdM2 > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the lamp's luminance {} cd/m^2 is not a positive number",
                                     luminanceCdM2));
    }
    LiveChainOptions options;
    options.averageSpectra = 1; // each reading once; the median does the averaging
    LiveSpectrometerChain chain(cal, instrument, options);
    std::vector<double> best, run;
    colour::Spectrum runFirst;
    for (const auto& raw : spectra) {
        auto spd = chain.add(raw);
        if (!spd) {
            continue; // saturated or malformed: not a reading of the level
        }
        if (run.empty() || spectralShapeDistance(runFirst, *spd) > options.steadyDistance) {
            run.clear();
            runFirst = *spd;
        }
        run.push_back(colour::spectrumToXyz(observer, *spd).y);
        if (run.size() > best.size()) {
            best = run;
        }
    }
    constexpr std::size_t kMinSpectra = 5;
    if (best.size() < kMinSpectra) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("no {} consecutive readings of one steady light (longest run "
                                     "{}); record the metered lamp alone for a few seconds",
                                     kMinSpectra, best.size()));
    }
    std::sort(best.begin(), best.end());
    const std::size_t n = best.size();
    const double median = n % 2 == 1 ? best[n / 2] : 0.5 * (best[n / 2 - 1] + best[n / 2]);
    if (!(median > 0.0) || !std::isfinite(median)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the readings' median Y is {}: no light reached the "
                                     "instrument; record the lamp switched on",
                                     median));
    }
    DirectLevelCalibration c;
    c.medianY = median;
    c.cdm2PerY = luminanceCdM2 / median;
    c.spectra = static_cast<int>(n);
    c.spreadFraction = (best.back() - best.front()) / median;
    return c;
}

} // namespace replica::pipeline::spectral
