// The live spectrometer chain: corrections from the instrument's calibration, averaging while the
// light is steady.
#include <algorithm>
#include <cmath>

#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/live_chain.h>

namespace replica::pipeline::spectral {
namespace {

// The per-pixel mean of the window's counts, rounded as the instrument's counts are.
std::vector<std::uint16_t> meanCounts(const std::deque<std::vector<std::uint16_t>>& window)
{
    std::vector<double> sum(window.front().size(), 0.0);
    for (const auto& w : window) {
        for (std::size_t i = 0; i < w.size() && i < sum.size(); ++i) {
            sum[i] += w[i];
        }
    }
    std::vector<std::uint16_t> mean(sum.size(), 0);
    for (std::size_t i = 0; i < sum.size(); ++i) {
        mean[i] = static_cast<std::uint16_t>(
                std::clamp(std::round(sum[i] / static_cast<double>(window.size())), 0.0, 65535.0));
    }
    return mean;
}

} // namespace

LiveSpectrometerChain::LiveSpectrometerChain(SpectrometerCalibration calibration,
                                             InstrumentCalibration instrument,
                                             LiveChainOptions options)
    : calibration_(std::move(calibration)), instrument_(instrument), options_(options),
      offsetNm_(instrument.wavelengthOffsetNm)
{
    options_.averageSpectra = std::max(options_.averageSpectra, 1);
}

ChainOptions LiveSpectrometerChain::chainOptions() const
{
    ChainOptions o;
    o.strayLightFraction = options_.strayLight ? instrument_.strayLightFraction : 0.0;
    // The shift the lines last gave (the calibration's until then); without the line search, the
    // calibration's.
    o.wavelengthOffsetNm = options_.wavelengthLines ? offsetNm_ : instrument_.wavelengthOffsetNm;
    return o;
}

Expected<colour::Spectrum> LiveSpectrometerChain::convert(const RawSpectrum& raw) const
{
    return countsToSpectrum(raw, calibration_, chainOptions());
}

Expected<colour::Spectrum> LiveSpectrometerChain::add(const RawSpectrum& raw)
{
    auto single = convert(raw);
    if (!single) {
        return single;
    }
    if (options_.averageSpectra <= 1 && !options_.wavelengthLines) {
        return single;
    }
    const bool sameFormat = !window_.empty() && raw.counts.size() == window_.front().size() &&
                            raw.integrationTimeUs == format_.integrationTimeUs &&
                            raw.wavelengthCoeffs == format_.wavelengthCoeffs &&
                            raw.nonlinearityCoeffs == format_.nonlinearityCoeffs;
    std::vector<std::uint16_t> mean;
    RawSpectrum averaged = raw;
    if (sameFormat) {
        // The running average as it stands, against this spectrum's shape.
        mean = meanCounts(window_);
        averaged.counts = mean;
        auto current = convert(averaged);
        if (!current || spectralShapeDistance(*current, *single) > options_.steadyDistance) {
            window_.clear(); // another light: a new average starts with this spectrum alone
        }
    } else {
        window_.clear();
    }
    window_.emplace_back(raw.counts.begin(), raw.counts.end());
    while (static_cast<int>(window_.size()) > options_.averageSpectra) {
        window_.pop_front();
    }
    format_ = raw;
    format_.counts = {};
    mean = meanCounts(window_); // this spectrum alone when it starts an average
    averaged.counts = mean;
    if (options_.wavelengthLines) {
        // The lines of the average where it has them; else the shift last found (the error is the
        // instrument's, not the light's).
        if (const auto shift = estimateWavelengthOffset(averaged, calibration_, kMercuryLinesNm)) {
            offsetNm_ = *shift;
        }
    }
    return convert(averaged);
}

LiveSpectrometerChain::State LiveSpectrometerChain::state() const
{
    State s;
    s.window.assign(window_.begin(), window_.end());
    s.offsetNm = offsetNm_;
    s.integrationTimeUs = format_.integrationTimeUs;
    s.wavelengthCoeffs = format_.wavelengthCoeffs;
    s.nonlinearityCoeffs = format_.nonlinearityCoeffs;
    return s;
}

void LiveSpectrometerChain::restore(const State& s)
{
    window_.assign(s.window.begin(), s.window.end());
    offsetNm_ = s.offsetNm;
    format_ = RawSpectrum{};
    format_.integrationTimeUs = s.integrationTimeUs;
    format_.wavelengthCoeffs = s.wavelengthCoeffs;
    format_.nonlinearityCoeffs = s.nonlinearityCoeffs;
}

} // namespace replica::pipeline::spectral

namespace replica::pipeline::spectral {

std::optional<ShiftCalibration> calibrateWavelengthShift(std::span<const RawSpectrum> spectra,
                                                         const SpectrometerCalibration& cal,
                                                         int group)
{
    std::vector<double> shifts;
    std::deque<std::vector<std::uint16_t>> run;
    const RawSpectrum* first = nullptr;
    auto close = [&] {
        if (first != nullptr && static_cast<int>(run.size()) >= std::max(group, 1)) {
            const std::vector<std::uint16_t> mean = meanCounts(run);
            RawSpectrum averaged = *first;
            averaged.counts = mean;
            if (const auto shift = estimateWavelengthOffset(averaged, cal, kMercuryLinesNm)) {
                shifts.push_back(*shift);
            }
        }
        run.clear();
        first = nullptr;
    };
    for (const auto& s : spectra) {
        const bool saturated =
                std::find(s.counts.begin(), s.counts.end(), std::uint16_t{65535}) != s.counts.end();
        if (saturated) {
            close();
            continue;
        }
        if (first != nullptr && (s.integrationTimeUs != first->integrationTimeUs ||
                                 s.counts.size() != first->counts.size() ||
                                 s.wavelengthCoeffs != first->wavelengthCoeffs)) {
            close();
        }
        if (first == nullptr) {
            first = &s;
        }
        run.emplace_back(s.counts.begin(), s.counts.end());
        if (static_cast<int>(run.size()) >= std::max(group, 1)) {
            close();
        }
    }
    if (shifts.empty()) {
        return std::nullopt;
    }
    std::sort(shifts.begin(), shifts.end());
    const std::size_t n = shifts.size();
    ShiftCalibration c;
    c.offsetNm = n % 2 == 1 ? shifts[n / 2] : 0.5 * (shifts[n / 2 - 1] + shifts[n / 2]);
    c.runs = static_cast<int>(n);
    c.spreadNm = shifts.back() - shifts.front();
    return c;
}

std::optional<double> strayLightFromLongPass(std::span<const RawSpectrum> spectra,
                                             const SpectrometerCalibration& cal,
                                             double cutOnNm)
{
    double below = 0.0;
    double peak = 0.0;
    int used = 0;
    for (const auto& s : spectra) {
        // The linearised, dark-subtracted counts (a stray-light fraction is of the counts).
        const auto n = static_cast<int>(s.counts.size());
        if (n <= cal.darkPixelLast + 2 || s.integrationTimeUs == 0) {
            continue;
        }
        double dark = 0.0;
        for (int p = cal.darkPixelFirst; p <= cal.darkPixelLast; ++p) {
            dark += s.counts[static_cast<std::size_t>(p)];
        }
        dark /= cal.darkPixelLast - cal.darkPixelFirst + 1;
        const auto& c = s.wavelengthCoeffs;
        const double edge = c[0] + 20.0;
        double sum = 0.0;
        double top = 0.0;
        int count = 0;
        for (int p = cal.darkPixelLast + 1; p < n; ++p) {
            const double x = p;
            const double wl = c[0] + x * (c[1] + x * (c[2] + x * c[3]));
            const double signal = s.counts[static_cast<std::size_t>(p)] - dark;
            double poly = 0.0;
            for (std::size_t i = s.nonlinearityCoeffs.size(); i-- > 0;) {
                poly = poly * signal + s.nonlinearityCoeffs[i];
            }
            const double linear = poly > 1e-6 ? signal / poly : signal;
            top = std::max(top, linear);
            if (wl >= edge && wl <= cutOnNm - 20.0) {
                sum += linear;
                ++count;
            }
        }
        if (count == 0 || !(top > 0.0)) {
            continue;
        }
        below += sum / count;
        peak += top;
        ++used;
    }
    if (used == 0 || !(peak > 0.0)) {
        return std::nullopt;
    }
    return std::max(below / peak, 0.0);
}

} // namespace replica::pipeline::spectral
