// A pixel-level USB2000+ and the appliance's chain back to the working grid.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include <fmt/format.h>

#include <pipeline/base/interpolate.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/offline/spectral/band_noise.h>
#include <pipeline/offline/spectral/sensed_light.h>
#include <pipeline/spectral/live_chain.h>
#include <pipeline/spectral/spectrometer_chain.h>

namespace replica::pipeline::spectral {
namespace {

// The instrument. The wavelength polynomial is a typical USB2000+ one (the simulated device in
// hal/sim uses the same); pixels 6..20 are optically masked.
constexpr std::array<double, 4> kCoeffs{339.2, 0.3797, -1.62e-5, -1.3e-10};
constexpr int kPixels = 2048;
constexpr int kDarkFirst = 6;
constexpr int kDarkLast = 20;
constexpr double kDarkOffsetCounts = 1500.0;
constexpr double kDarkCurrentCountsPerS = 200.0;
constexpr double kReadNoiseCounts = 50.0;     // data sheet: dark noise 50 counts rms
constexpr double kShotVariancePerCount = 0.8; // SNR 250:1 at full signal
constexpr double kNonlinearityK = -2.0e-6;    // corrected exactly by the EEPROM's 1 + k m
constexpr double kBowFullScale = 60000.0;     // the residual bow is 0 at 0 and here
// The lamp brings the brightest pixel to full scale in about 0.16 s: auto-integration settles
// near 0.12 s, inside the paper's five spectra a second.
constexpr double kPeakRateCountsPerS = 400'000.0;
constexpr std::uint32_t kStartIntegrationUs = 100'000;

double reported(double p)
{
    return kCoeffs[0] + p * (kCoeffs[1] + p * (kCoeffs[2] + p * kCoeffs[3]));
}

// Grating and detector efficiency (the band-noise model's bell, continuous in wavelength).
double responsivity(double nm)
{
    const double x = (nm - 550.0) / 150.0;
    return 0.2 + 0.8 * std::exp(-0.5 * x * x * 1.6);
}

double normalCdf(double z)
{
    return 0.5 * std::erfc(-z / std::numbers::sqrt2);
}

} // namespace

Expected<FineLight>
restoreLines(const colour::SpectralTable& table, const std::string& column, double excess)
{
    const auto it = std::find(table.columns.begin(), table.columns.end(), column);
    if (it == table.columns.end()) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no column '{}'", table.source, column));
    }
    const auto c = static_cast<std::size_t>(it - table.columns.begin());
    FineLight light;
    light.name = column;
    light.wavelengthNm = table.wavelengthNm;
    for (const auto& row : table.rows) {
        light.continuum.push_back(row[c]);
    }
    const std::size_t n = light.wavelengthNm.size();
    if (n < 3) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: too few samples to look for lines", table.source));
    }
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const double step = 0.5 * (light.wavelengthNm[i + 1] - light.wavelengthNm[i - 1]);
        for (double hg : kMercuryLinesNm) {
            if (std::abs(light.wavelengthNm[i] - hg) > 0.5 * step + 1e-9) {
                continue;
            }
            const double base = 0.5 * (light.continuum[i - 1] + light.continuum[i + 1]);
            const double over = light.continuum[i] - base;
            if (over > excess * std::max(base, 0.0) && over > 0.0) {
                light.continuum[i] = base;
                light.lines.emplace_back(hg, over * step);
            }
        }
    }
    return light;
}

Expected<colour::Spectrum> fineLightToWorkingGrid(const FineLight& light)
{
    if (light.wavelengthNm.size() < 2 || light.continuum.size() != light.wavelengthNm.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: a fine light needs two samples or more", light.name));
    }
    // The continuum is linear between its samples (as the instrument sees it): integrate that, on
    // a 0.05 nm grid, rather than the samples themselves.
    colour::SampledSpectrum s;
    const double first = light.wavelengthNm.front();
    const double last = light.wavelengthNm.back();
    const auto steps = static_cast<std::size_t>(std::floor((last - first) / 0.05));
    for (std::size_t i = 0; i <= steps; ++i) {
        const double nm = first + 0.05 * static_cast<double>(i);
        s.wavelengthNm.push_back(nm);
        s.value.push_back(
                interpolateLinear(light.wavelengthNm, light.continuum, nm, Outside::Clamp));
    }
    auto out = colour::resampleToWorkingGrid(s, light.name, colour::GridSampling::BandAverage);
    if (!out) {
        return out;
    }
    // A line of power E adds E * triangle(distance) / (triangle area 10 nm) to each band.
    for (const auto& [nm, power] : light.lines) {
        for (std::size_t b = 0; b < colour::kBands; ++b) {
            const double d = std::abs(nm - colour::bandCentreNm(b));
            if (d < 10.0) {
                out->v[b] += power * (1.0 - d / 10.0) / 10.0;
            }
        }
    }
    return out;
}

double drawWavelengthError(double maxNm, std::uint64_t seed)
{
    NoiseSource noise(seed ^ 0x5bd1e995ULL);
    return maxNm * (2.0 * noise.uniform() - 1.0);
}

InstrumentImpairments idealInstrument()
{
    InstrumentImpairments i;
    i.fwhmNm = 0.0;
    i.wavelengthErrorNm = 0.0;
    i.strayFraction = 0.0;
    i.noise = false;
    i.residualNonlinearity = 0.0;
    return i;
}

namespace {

// Each pixel's photo-electron rate (counts per second, the brightest pixel at
// kPeakRateCountsPerS) for the light through the instrument's optics.
Expected<std::vector<double>> pixelRates(const FineLight& light, const InstrumentImpairments& imp)
{
    // Each pixel's true centre and edges (midway to its neighbours).
    std::vector<double> centre(kPixels);
    for (int p = 0; p < kPixels; ++p) {
        centre[static_cast<std::size_t>(p)] = reported(p) + imp.wavelengthErrorNm;
    }
    const double sigma = imp.fwhmNm / (2.0 * std::sqrt(2.0 * std::numbers::ln2));
    std::vector<double> rate(kPixels, 0.0); // counts per second, before stray light
    double peakRate = 0.0;
    for (int p = kDarkLast + 1; p < kPixels; ++p) {
        const auto i = static_cast<std::size_t>(p);
        const double lo = p > 0 ? 0.5 * (centre[i - 1] + centre[i]) : centre[i];
        const double hi = p + 1 < kPixels ? 0.5 * (centre[i] + centre[i + 1]) : centre[i];
        const double width = hi - lo;
        // The continuum through the line-spread function (13-point quadrature over +-3 sigma).
        double cont = 0.0;
        if (sigma > 0.0) {
            double wsum = 0.0;
            for (int k = -6; k <= 6; ++k) {
                const double z = k * 0.5;
                const double w = std::exp(-0.5 * z * z);
                cont += w * interpolateLinear(light.wavelengthNm, light.continuum,
                                              centre[i] + z * sigma, Outside::Clamp);
                wsum += w;
            }
            cont /= wsum;
        } else {
            cont = interpolateLinear(light.wavelengthNm, light.continuum, centre[i],
                                     Outside::Clamp);
        }
        // Lines: the part of the line-spread function that falls on this pixel.
        double lines = 0.0;
        for (const auto& [nm, power] : light.lines) {
            double share = 0.0;
            if (sigma > 0.0) {
                share = normalCdf((hi - nm) / sigma) - normalCdf((lo - nm) / sigma);
            } else {
                share = nm >= lo && nm < hi ? 1.0 : 0.0;
            }
            lines += power * share / std::max(width, 1e-9);
        }
        rate[i] = (cont + lines) * responsivity(centre[i]);
        peakRate = std::max(peakRate, rate[i]);
    }
    if (!(peakRate > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no light reaches the detector", light.name));
    }
    for (double& r : rate) {
        r *= kPeakRateCountsPerS / peakRate;
    }
    return rate;
}

// The detector reading the light: one scan at a time, as counts.
class Detector
{
public:
    Detector(std::vector<double> rate, const InstrumentImpairments& imp, std::uint64_t seed)
        : rate_(std::move(rate)), imp_(imp), noise_(seed), counts_(kPixels, 0)
    {}
    // One scan of 'us' microseconds into counts(); returns its brightest raw pixel.
    double scan(std::uint32_t us)
    {
        const double t = us * 1e-6;
        const double strayRate = imp_.strayFraction * kPeakRateCountsPerS;
        const double noiseScale = imp_.noise ? 1.0 : 0.0;
        double peak = 0.0;
        for (int p = 0; p < kPixels; ++p) {
            const auto i = static_cast<std::size_t>(p);
            const double photo = p > kDarkLast ? (rate_[i] + strayRate) * t : 0.0;
            const double charge = photo + kDarkCurrentCountsPerS * t;
            const double g1 = noise_.gaussian();
            const double g2 = noise_.gaussian();
            const double x = charge + noiseScale * std::sqrt(kShotVariancePerCount * charge) * g1;
            const double compressed = x / (1.0 - kNonlinearityK * x);
            const double u = std::clamp(x / kBowFullScale, 0.0, 1.0);
            const double measured =
                    compressed * (1.0 + imp_.residualNonlinearity * 4.0 * u * (1.0 - u));
            const double value = std::clamp(
                    std::round(kDarkOffsetCounts + measured + noiseScale * kReadNoiseCounts * g2),
                    0.0, 65535.0);
            counts_[i] = static_cast<std::uint16_t>(value);
            peak = std::max(peak, value);
        }
        return peak;
    }
    const std::vector<std::uint16_t>& counts() const { return counts_; }
    double darkMean() const
    {
        double d = 0.0;
        for (int p = kDarkFirst; p <= kDarkLast; ++p) {
            d += counts_[static_cast<std::size_t>(p)];
        }
        return d / (kDarkLast - kDarkFirst + 1);
    }
    // Auto-integration, as the appliance runs it: read, adjust, until the time stays.
    std::uint32_t settle()
    {
        std::uint32_t us = kStartIntegrationUs;
        for (int round = 0; round < 12; ++round) {
            scan(us);
            const AutoIntegrationDecision d = nextIntegrationTime(counts_, darkMean(), us);
            if (!d.changed) {
                break;
            }
            us = d.integrationTimeUs;
        }
        return us;
    }

private:
    std::vector<double> rate_;
    InstrumentImpairments imp_;
    NoiseSource noise_;
    std::vector<std::uint16_t> counts_;
};

// The simulated instrument's EEPROM and responsivity calibration, as the appliance reads them.
SpectrometerCalibration simulatedCalibration()
{
    SpectrometerCalibration cal;
    for (double nm = 330.0; nm <= 1120.0; nm += 1.0) {
        cal.wavelengthNm.push_back(nm);
        cal.responsivity.push_back(responsivity(nm));
    }
    cal.darkPixelFirst = kDarkFirst;
    cal.darkPixelLast = kDarkLast;
    return cal;
}

RawSpectrum rawSpectrum(std::span<const std::uint16_t> counts, std::uint32_t us)
{
    RawSpectrum raw;
    raw.counts = counts;
    raw.integrationTimeUs = us;
    raw.wavelengthCoeffs = kCoeffs;
    raw.nonlinearityCoeffs = {1.0, kNonlinearityK, 0, 0, 0, 0, 0, 0};
    return raw;
}

// The study's own chain: the scans' counts averaged, then countsToSpectrum with the corrections
// asked for.
Expected<colour::Spectrum> studyChain(Detector& detector,
                                      std::uint32_t us,
                                      const InstrumentImpairments& imp,
                                      const SensingCorrections& corr,
                                      SensedLight& out)
{
    std::vector<double> sum(kPixels, 0.0);
    for (int s = 0; s < corr.scansAveraged; ++s) {
        out.peakCounts = detector.scan(us);
        for (int p = 0; p < kPixels; ++p) {
            sum[static_cast<std::size_t>(p)] += detector.counts()[static_cast<std::size_t>(p)];
        }
    }
    std::vector<std::uint16_t> counts(kPixels, 0);
    for (int p = 0; p < kPixels; ++p) {
        const double mean = sum[static_cast<std::size_t>(p)] / corr.scansAveraged;
        counts[static_cast<std::size_t>(p)] =
                static_cast<std::uint16_t>(std::clamp(std::round(mean), 0.0, 65535.0));
    }
    out.scansAveraged = corr.scansAveraged;
    const RawSpectrum raw = rawSpectrum(counts, us);
    const SpectrometerCalibration cal = simulatedCalibration();
    ChainOptions options;
    if (corr.strayLight) {
        options.strayLightFraction = imp.strayFraction;
    }
    if (corr.wavelengthLines) {
        if (const auto shift = estimateWavelengthOffset(raw, cal, kMercuryLinesNm)) {
            options.wavelengthOffsetNm = *shift;
            out.wavelengthFoundNm = *shift;
            out.linesFound = true;
        } else if (std::isfinite(corr.rememberedOffsetNm)) {
            options.wavelengthOffsetNm = corr.rememberedOffsetNm;
            out.wavelengthFoundNm = corr.rememberedOffsetNm;
        }
    }
    return countsToSpectrum(raw, cal, options);
}

// The simulated instrument pointed at 'light', its integration time settled as the appliance's
// auto-integration settles it: what senseLight and the simulated shift calibration both start
// from, so that the two see one instrument.
struct SettledDetector {
    Detector detector;
    std::uint32_t integrationTimeUs = 0;
};

Expected<SettledDetector>
settledDetector(const FineLight& light, const InstrumentImpairments& imp, std::uint64_t seed)
{
    auto rate = pixelRates(light, imp);
    if (!rate) {
        return tl::unexpected(rate.error());
    }
    SettledDetector settled{Detector(std::move(*rate), imp, seed), 0};
    settled.integrationTimeUs = settled.detector.settle();
    return settled;
}

// The appliance's own chain (LiveSpectrometerChain with its defaults), fed one scan at a time
// for scansAveraged scans of the steady light, calibrated with the instrument's characterised
// stray light and the shift remembered from the site's calibration.
Expected<colour::Spectrum> applianceChain(Detector& detector,
                                          std::uint32_t us,
                                          const InstrumentImpairments& imp,
                                          const SensingCorrections& corr,
                                          SensedLight& out)
{
    InstrumentCalibration instrument;
    instrument.strayLightFraction = imp.strayFraction;
    instrument.wavelengthOffsetNm =
            std::isfinite(corr.rememberedOffsetNm) ? corr.rememberedOffsetNm : 0.0;
    LiveSpectrometerChain chain(simulatedCalibration(), instrument, corr.chain);
    Expected<colour::Spectrum> spd = makeError(ErrorCode::InvalidArgument, "no scan");
    for (int s = 0; s < corr.scansAveraged; ++s) {
        out.peakCounts = detector.scan(us);
        spd = chain.add(rawSpectrum(detector.counts(), us));
        if (!spd) {
            return spd;
        }
    }
    out.wavelengthFoundNm = chain.wavelengthOffsetNm();
    out.scansAveraged = chain.averaged();
    return spd;
}

} // namespace

Expected<SensedLight> senseLight(const FineLight& light,
                                 const colour::Observer& observer,
                                 const InstrumentImpairments& imp,
                                 const SensingCorrections& corr,
                                 std::uint64_t seed)
{
    if (light.wavelengthNm.size() < 2 || light.continuum.size() != light.wavelengthNm.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: a fine light needs two samples or more", light.name));
    }
    if (!(imp.fwhmNm >= 0.0) || !(imp.strayFraction >= 0.0) || !(imp.strayFraction < 1.0) ||
        !(std::abs(imp.wavelengthErrorNm) <= 5.0) || corr.scansAveraged < 1) {
        return makeError(ErrorCode::InvalidArgument,
                         "sensed light: FWHM and stray light must be >= 0, the wavelength error "
                         "within 5 nm and at least one scan averaged");
    }
    auto settled = settledDetector(light, imp, seed);
    if (!settled) {
        return tl::unexpected(settled.error());
    }
    Detector& detector = settled->detector;
    SensedLight out;
    out.integrationTimeUs = settled->integrationTimeUs;
    auto spd = corr.applianceChain ? applianceChain(detector, out.integrationTimeUs, imp, corr, out)
                                   : studyChain(detector, out.integrationTimeUs, imp, corr, out);
    if (!spd) {
        return tl::unexpected(spd.error());
    }
    auto realSpd = fineLightToWorkingGrid(light);
    if (!realSpd) {
        return tl::unexpected(realSpd.error());
    }
    const double yReal = colour::spectrumToXyz(observer, *realSpd).y;
    const double ySensed = colour::spectrumToXyz(observer, *spd).y;
    if (!(ySensed > 0.0) || !(yReal > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the sensed light has no luminance", light.name));
    }
    out.spd = *spd * (yReal / ySensed);
    return out;
}

Expected<std::optional<ShiftCalibration>>
calibrateShiftOnSimulatedInstrument(const FineLight& light,
                                    const InstrumentImpairments& imp,
                                    int scans,
                                    int group,
                                    std::uint64_t seed)
{
    if (scans < 1 || group < 1 || !(std::abs(imp.wavelengthErrorNm) <= 5.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "simulated calibration: at least one scan and a group of one, the "
                         "wavelength error within 5 nm");
    }
    auto settled = settledDetector(light, imp, seed);
    if (!settled) {
        return tl::unexpected(settled.error());
    }
    Detector& detector = settled->detector;
    const std::uint32_t us = settled->integrationTimeUs;
    // The counts outlive the spans the raw spectra hold.
    std::vector<std::vector<std::uint16_t>> counts;
    counts.reserve(static_cast<std::size_t>(scans));
    for (int s = 0; s < scans; ++s) {
        detector.scan(us);
        counts.push_back(detector.counts());
    }
    std::vector<RawSpectrum> raw;
    raw.reserve(counts.size());
    for (const auto& c : counts) {
        raw.push_back(rawSpectrum(c, us));
    }
    return calibrateWavelengthShift(raw, simulatedCalibration(), group);
}

} // namespace replica::pipeline::spectral
