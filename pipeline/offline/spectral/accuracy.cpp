// Representation accuracy with the paper's white normalisation and CAT02 to D65.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <pipeline/colour/cat02.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/offline/spectral/accuracy.h>

namespace replica::pipeline::spectral {
namespace {

constexpr double kWhiteY = 1.0 / 1.13; // the paper's "multiplying by a factor of 1.13", inverted

} // namespace

ErrorStats errorStats(std::vector<double> values)
{
    ErrorStats s;
    if (values.empty()) {
        return s;
    }
    const double n = static_cast<double>(values.size());
    double sum = 0.0;
    for (double v : values) {
        sum += v;
    }
    s.mean = sum / n;
    double var = 0.0;
    for (double v : values) {
        var += (v - s.mean) * (v - s.mean);
    }
    s.std = std::sqrt(var / n);
    std::sort(values.begin(), values.end());
    const double rank = 0.9 * (n - 1.0);
    const auto lo = static_cast<std::size_t>(std::floor(rank));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    const double frac = rank - static_cast<double>(lo);
    s.p90 = values[lo] + frac * (values[hi] - values[lo]);
    s.max = values.back();
    return s;
}

std::size_t
whiteSampleIndex(const Observer& obs, const Spectrum& light, const NamedSpectra& samples)
{
    for (std::size_t i = 0; i < samples.size(); ++i) {
        if (samples.names[i] == "white") {
            return i;
        }
    }
    std::size_t best = 0;
    double bestY = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const double y = colour::spectrumToXyz(obs, light * samples.spectra[i]).y;
        if (y > bestY) {
            bestY = y;
            best = i;
        }
    }
    return best;
}

Expected<std::vector<colour::Lab>> normalisedLab(const std::vector<Xyz>& xyz,
                                                 std::size_t whiteIndex,
                                                 const Xyz& lightXyz,
                                                 const Xyz& d65Xyz)
{
    if (whiteIndex >= xyz.size() || !(xyz[whiteIndex].y > 0.0)) {
        return makeError(ErrorCode::InvalidArgument, "accuracy: the white sample has no luminance "
                                                     "(Y <= 0), so nothing can be normalised");
    }
    if (!(lightXyz.y > 0.0) || !(d65Xyz.y > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "accuracy: the light has no luminance (Y <= 0)");
    }
    const double scale = kWhiteY / xyz[whiteIndex].y;
    const Xyz source = lightXyz * (1.0 / lightXyz.y);
    const Xyz target = d65Xyz * (1.0 / d65Xyz.y);
    const colour::Matrix3 cat = colour::cat02AdaptationMatrix(source, target, 1.0);
    std::vector<colour::Lab> lab;
    lab.reserve(xyz.size());
    for (const Xyz& v : xyz) {
        lab.push_back(colour::xyzToLab(colour::applyMatrix(cat, v * scale), target));
    }
    return lab;
}

Expected<AccuracyReport> evaluateRepresentation(const Observer& obs,
                                                const Spectrum& d65,
                                                const Representation& approx,
                                                const Spectrum& light,
                                                const NamedSpectra& samples)
{
    if (samples.spectra.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the reflectance set is empty", samples.source));
    }
    const Xyz lightXyz = colour::spectrumToXyz(obs, light);
    if (!(lightXyz.y > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "accuracy: the light has no luminance (Y <= 0); is it all zeros?");
    }
    const Xyz d65Xyz = colour::spectrumToXyz(obs, d65);
    // An adaptive representation is evaluated as encoded for the light it renders under.
    auto adapted = approx.adaptedTo(light);
    if (!adapted) {
        return tl::unexpected(adapted.error());
    }
    const Representation& rep = *adapted ? **adapted : approx;
    const std::vector<Xyz> lightVectors = rep.lightVectors(light);
    std::vector<Xyz> reference;
    std::vector<Xyz> approximate;
    for (const auto& r : samples.spectra) {
        reference.push_back(colour::spectrumToXyz(obs, light * r) * (1.0 / lightXyz.y));
        approximate.push_back(shade(rep.encode(r), lightVectors));
    }
    AccuracyReport report;
    report.representation = approx.name();
    report.whiteIndex = whiteSampleIndex(obs, light, samples);
    report.adaptation = colour::adaptationBetween(lightXyz, d65Xyz);
    auto labRef = normalisedLab(reference, report.whiteIndex, lightXyz, d65Xyz);
    if (!labRef) {
        return tl::unexpected(labRef.error());
    }
    auto labApprox = normalisedLab(approximate, report.whiteIndex, lightXyz, d65Xyz);
    if (!labApprox) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("accuracy: representation '{}' gives the white sample no luminance",
                            approx.name()));
    }
    std::vector<double> de;
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const double d = colour::ciede2000((*labRef)[i], (*labApprox)[i]);
        report.samples.push_back(
                SampleAccuracy{samples.names[i], (*labRef)[i], (*labApprox)[i], d});
        de.push_back(d);
    }
    report.stats = errorStats(std::move(de));
    return report;
}

} // namespace replica::pipeline::spectral
