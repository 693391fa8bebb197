// Raw spectrometer counts to a working-grid relative SPD.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <pipeline/base/interpolate.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/spectral/spectrometer_chain.h>

namespace replica::pipeline::spectral {

Expected<SpectrometerCalibration> loadSpectrometerCalibration(const std::filesystem::path& path)
{
    auto table = colour::loadSpectralCsv(path);
    if (!table) {
        return tl::unexpected(table.error());
    }
    if (table->columns.size() != 1 || table->columns[0] != "responsivity") {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("{}: expected columns wavelength_nm,responsivity", path.string()));
    }
    SpectrometerCalibration cal;
    cal.wavelengthNm = table->wavelengthNm;
    for (const auto& row : table->rows) {
        if (!(row[0] > 0.0)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}: responsivity must be positive everywhere", path.string()));
        }
        cal.responsivity.push_back(row[0]);
    }
    return cal;
}

SignalLevel signalLevel(std::span<const std::uint16_t> counts, const SpectrometerCalibration& cal)
{
    const auto n = static_cast<int>(counts.size());
    if (n <= cal.darkPixelLast + 1 || cal.darkPixelFirst < 0 ||
        cal.darkPixelLast < cal.darkPixelFirst) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        return {nan, nan};
    }
    const auto dark =
            counts.subspan(static_cast<std::size_t>(cal.darkPixelFirst),
                           static_cast<std::size_t>(cal.darkPixelLast - cal.darkPixelFirst + 1));
    double mean = 0.0;
    for (const std::uint16_t c : dark) {
        mean += c;
    }
    mean /= static_cast<double>(dark.size());
    double var = 0.0;
    for (const std::uint16_t c : dark) {
        var += (c - mean) * (c - mean);
    }
    var /= static_cast<double>(std::max<std::size_t>(dark.size() - 1, 1));
    const auto light = counts.subspan(static_cast<std::size_t>(cal.darkPixelLast + 1));
    return {static_cast<double>(*std::max_element(light.begin(), light.end())) - mean,
            std::sqrt(var)};
}

Expected<colour::Spectrum> countsToSpectrum(const RawSpectrum& raw,
                                            const SpectrometerCalibration& cal)
{
    return countsToSpectrum(raw, cal, ChainOptions{});
}

Expected<colour::Spectrum> countsToSpectrum(const RawSpectrum& raw,
                                            const SpectrometerCalibration& cal,
                                            const ChainOptions& options)
{
    const auto n = static_cast<int>(raw.counts.size());
    if (n <= cal.darkPixelLast + 2 || cal.darkPixelFirst < 0 ||
        cal.darkPixelLast < cal.darkPixelFirst) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("spectrum has {} pixels; too few for dark pixels {}..{}", n,
                                     cal.darkPixelFirst, cal.darkPixelLast));
    }
    if (raw.integrationTimeUs == 0) {
        return makeError(ErrorCode::InvalidArgument, "spectrum has an integration time of 0 us");
    }
    double dark = 0.0;
    for (int p = cal.darkPixelFirst; p <= cal.darkPixelLast; ++p) {
        dark += raw.counts[static_cast<std::size_t>(p)];
    }
    dark /= static_cast<double>(cal.darkPixelLast - cal.darkPixelFirst + 1);

    const double seconds = static_cast<double>(raw.integrationTimeUs) * 1e-6;
    colour::SampledSpectrum s;
    s.wavelengthNm.reserve(static_cast<std::size_t>(n));
    s.value.reserve(static_cast<std::size_t>(n));
    const auto& c = raw.wavelengthCoeffs;
    for (int p = cal.darkPixelLast + 1; p < n; ++p) {
        const double x = p;
        const double wl = c[0] + options.wavelengthOffsetNm + x * (c[1] + x * (c[2] + x * c[3]));
        if (!s.wavelengthNm.empty() && !(wl > s.wavelengthNm.back())) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("wavelength calibration is not increasing at pixel {}", p));
        }
        const double signal = raw.counts[static_cast<std::size_t>(p)] - dark;
        double poly = 0.0;
        for (std::size_t i = raw.nonlinearityCoeffs.size(); i-- > 0;) {
            poly = poly * signal + raw.nonlinearityCoeffs[i];
        }
        // A non-linearity polynomial that is not positive here is unusable; fall back to no
        // correction.
        const double corrected = poly > 1e-6 ? signal / poly : signal;
        s.wavelengthNm.push_back(wl);
        s.value.push_back(corrected);
    }
    if (!(options.strayLightFraction >= 0.0) || !(options.strayLightFraction < 1.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("stray-light fraction {} is outside [0, 1)",
                                     options.strayLightFraction));
    }
    if (options.strayLightFraction > 0.0 && !s.value.empty()) {
        // measured = true + f * peak(true) on every pixel, so peak(measured) = (1 + f) peak(true).
        const double peak = *std::max_element(s.value.begin(), s.value.end());
        const double stray = std::max(peak, 0.0) * options.strayLightFraction /
                             (1.0 + options.strayLightFraction);
        for (double& v : s.value) {
            v -= stray;
        }
    }
    if (options.boxcarHalfWidth < 0) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("boxcar half-width {} is negative", options.boxcarHalfWidth));
    }
    if (options.boxcarHalfWidth > 0) {
        // Running mean over the pixels present (the window shrinks at the ends rather than
        // inventing data).
        const std::vector<double> linear = s.value;
        const auto count = static_cast<std::ptrdiff_t>(linear.size());
        const auto w = static_cast<std::ptrdiff_t>(options.boxcarHalfWidth);
        for (std::ptrdiff_t i = 0; i < count; ++i) {
            const std::ptrdiff_t lo = std::max<std::ptrdiff_t>(0, i - w);
            const std::ptrdiff_t hi = std::min<std::ptrdiff_t>(count - 1, i + w);
            double sum = 0.0;
            for (std::ptrdiff_t j = lo; j <= hi; ++j) {
                sum += linear[static_cast<std::size_t>(j)];
            }
            s.value[static_cast<std::size_t>(i)] = sum / static_cast<double>(hi - lo + 1);
        }
    }
    for (std::size_t i = 0; i < s.value.size(); ++i) {
        const double r = interpolateLinear(cal.wavelengthNm, cal.responsivity, s.wavelengthNm[i],
                                           Outside::Zero);
        s.value[i] = r > 1e-9 ? s.value[i] / (seconds * r) : 0.0;
    }
    return colour::resampleToWorkingGrid(s, "spectrometer", colour::GridSampling::BandAverage);
}

std::optional<double> estimateWavelengthOffset(const RawSpectrum& raw,
                                               const SpectrometerCalibration& cal,
                                               std::span<const double> linesNm,
                                               const LineSearchOptions& options)
{
    const auto n = static_cast<int>(raw.counts.size());
    if (n <= cal.darkPixelLast + 8 || cal.darkPixelFirst < 0 ||
        cal.darkPixelLast < cal.darkPixelFirst) {
        return std::nullopt;
    }
    double dark = 0.0;
    for (int p = cal.darkPixelFirst; p <= cal.darkPixelLast; ++p) {
        dark += raw.counts[static_cast<std::size_t>(p)];
    }
    dark /= static_cast<double>(cal.darkPixelLast - cal.darkPixelFirst + 1);
    const auto& c = raw.wavelengthCoeffs;
    auto wavelength = [&](double x) { return c[0] + x * (c[1] + x * (c[2] + x * c[3])); };
    auto signal = [&](int p) { return raw.counts[static_cast<std::size_t>(p)] - dark; };
    double sum = 0.0;
    int found = 0;
    for (double line : linesNm) {
        // The brightest pixel within the search window.
        int best = -1;
        for (int p = cal.darkPixelLast + 2; p < n - 1; ++p) {
            const double wl = wavelength(p);
            if (std::abs(wl - line) <= options.searchNm && (best < 0 || signal(p) > signal(best))) {
                best = p;
            }
        }
        if (best < 0) {
            continue;
        }
        // The local baseline: the lowest signal within 4 nm either side.
        double baseline = signal(best);
        for (int p = cal.darkPixelLast + 1; p < n; ++p) {
            if (std::abs(wavelength(p) - wavelength(best)) <= 4.0) {
                baseline = std::min(baseline, signal(p));
            }
        }
        const double a = signal(best - 1) - baseline;
        const double b = signal(best) - baseline;
        const double d = signal(best + 1) - baseline;
        if (!(b > options.contrast * std::max(baseline, 1.0)) || !(a > 0.0) || !(d > 0.0) ||
            b < a || b < d) {
            continue; // no clear peak here
        }
        // Three-point Gaussian (parabola through the logarithms) for the sub-pixel centre.
        const double la = std::log(a);
        const double lb = std::log(b);
        const double ld = std::log(d);
        const double curvature = la - 2.0 * lb + ld;
        if (!(curvature < -1e-12)) {
            continue;
        }
        const double delta = std::clamp(0.5 * (la - ld) / curvature, -1.0, 1.0);
        sum += line - wavelength(best + delta);
        ++found;
    }
    if (found < std::max(options.minLines, 1)) {
        return std::nullopt;
    }
    return sum / found;
}

AutoIntegrationDecision nextIntegrationTime(std::span<const std::uint16_t> counts,
                                            double darkCounts,
                                            std::uint32_t currentUs,
                                            const AutoIntegrationParams& params)
{
    AutoIntegrationDecision d;
    d.integrationTimeUs = currentUs;
    double peak = 0.0;
    for (std::uint16_t c : counts) {
        peak = std::max(peak, static_cast<double>(c));
    }
    const double step = std::max<double>(params.stepUs, 1.0);
    auto quantise = [&](double us) {
        const double q = std::round(us / step) * step;
        return static_cast<std::uint32_t>(std::clamp(q, static_cast<double>(params.minUs),
                                                     static_cast<double>(params.maxUs)));
    };
    d.saturated = peak >= params.saturationCounts;
    double next = currentUs;
    if (d.saturated) {
        next = currentUs / 4.0;
    } else {
        const double signal = peak - darkCounts;
        const double target = params.targetFraction * params.saturationCounts - darkCounts;
        if (!(signal > 0.0)) {
            // Nothing above the dark level (lamp off, shutter closed): lengthen, but gently.
            next = currentUs * 2.0;
        } else if (std::abs(signal - target) > params.toleranceFraction * target) {
            // Counts above dark grow in proportion to the integration time.
            next = currentUs * target / signal;
            // Do not lengthen by more than 8x at once: a flicker or a passing shadow can fake a dim
            // scene, and a long integration would blind the next reading.
            next = std::min(next, currentUs * 8.0);
        }
    }
    d.integrationTimeUs = quantise(next);
    d.changed = d.integrationTimeUs != currentUs;
    return d;
}

} // namespace replica::pipeline::spectral
