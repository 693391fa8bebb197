// Display model fit: the measurements read into ramps and colours and checked, then the model
// candidates (display_fit_candidate.h, display_crosstalk_fit.h) and the report.
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <pipeline/display/xyz_difference.h>
#include <pipeline/offline/display/display_crosstalk_fit.h>
#include <pipeline/offline/display/display_fit.h>
#include <pipeline/offline/display/display_fit_candidate.h>
#include <pipeline/offline/display/display_fit_uncertainty.h>

namespace replica::pipeline::display {
namespace {

// Mean XYZ of repeated measurements of the same counts; keeps the first line number. 'repeats'
// receives how many readings each mean holds.
std::vector<Measurement> averageRepeats(const std::vector<Measurement>& rows,
                                        std::vector<int>& repeats)
{
    std::map<std::tuple<double, double, double>, std::pair<Measurement, int>> groups;
    std::vector<std::tuple<double, double, double>> order;
    for (const auto& m : rows) {
        const auto key = std::make_tuple(m.counts.x, m.counts.y, m.counts.z);
        auto it = groups.find(key);
        if (it == groups.end()) {
            groups.emplace(key, std::make_pair(m, 1));
            order.push_back(key);
        } else {
            it->second.first.xyz += m.xyz;
            ++it->second.second;
        }
    }
    std::vector<Measurement> out;
    repeats.clear();
    for (const auto& key : order) {
        auto [m, n] = groups.at(key);
        m.xyz /= static_cast<double>(n);
        out.push_back(m);
        repeats.push_back(n);
    }
    return out;
}

glm::dvec2 chromaticity(const glm::dvec3& xyz)
{
    const double s = xyz.x + xyz.y + xyz.z;
    return s > 0.0 ? glm::dvec2(xyz.x / s, xyz.y / s) : glm::dvec2(0.0);
}

// Black / flare offset: the (0,0,0) reading.
Expected<glm::dvec3> findBlack(const std::vector<Measurement>& rows, const std::string& src)
{
    const auto blackIt = std::find_if(rows.begin(), rows.end(), [](const Measurement& m) {
        return m.counts == glm::dvec3(0.0);
    });
    if (blackIt == rows.end()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no black (0,0,0) measurement: the black/flare offset "
                                     "cannot be fitted; measure the panel at 0,0,0",
                                     src));
    }
    return blackIt->xyz;
}

// The single-channel ramps, sorted by count and each reaching full drive, and the colours off
// them.
Expected<void> splitRamps(const std::vector<Measurement>& rows,
                          const std::vector<int>& repeats,
                          const FitOptions& options,
                          FitData& data)
{
    for (std::size_t row = 0; row < rows.size(); ++row) {
        const Measurement& m = rows[row];
        int nonZero = 0;
        int channel = 0;
        for (int c = 0; c < 3; ++c) {
            if (m.counts[c] > 0.0) {
                ++nonZero;
                channel = c;
            }
        }
        if (nonZero == 1) {
            data.ramps[static_cast<std::size_t>(channel)].push_back(
                    {m.counts[channel], m.xyz, m.line, repeats[row]});
        } else if (nonZero > 1) {
            data.colours.push_back(m);
        }
    }
    for (std::size_t c = 0; c < 3; ++c) {
        auto& r = data.ramps[c];
        std::sort(r.begin(), r.end(),
                  [](const RampPoint& a, const RampPoint& b) { return a.count < b.count; });
        const bool hasFull = !r.empty() && r.back().count == data.maxCount;
        const int need = options.toneMethod == ToneMethod::Robust ? options.minGogRampLevels
                                                                  : options.minRampLevels;
        if (static_cast<int>(r.size()) < need || !hasFull) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: missing ramp: channel {} has {} non-zero levels{} "
                                         "(needs at least {} with the others at 0, full drive "
                                         "{} included; {} for the cross-validated tone shapes); "
                                         "with ArgyllCMS, add single-channel steps: targen -d3 "
                                         "-s {} (0 to full drive in {} steps) with the rest of "
                                         "the set",
                                         data.source, kChannelNames[c], r.size(),
                                         hasFull ? "" : " and no full-drive point", need,
                                         data.maxCount, options.minRampLevels,
                                         options.minRampLevels + 1, options.minRampLevels + 1));
        }
    }
    return {};
}

// The primaries at full drive above black: none dead, the matrix not singular.
Expected<glm::dmat3> directPrimaries(const FitData& data, const FitOptions& options)
{
    std::array<glm::dvec3, 3> primary{};
    double total = 0.0;
    for (std::size_t c = 0; c < 3; ++c) {
        primary[c] = data.ramps[c].back().xyz - data.black;
        total += std::max(0.0, primary[c].x + primary[c].y + primary[c].z);
    }
    for (std::size_t c = 0; c < 3; ++c) {
        const double s = primary[c].x + primary[c].y + primary[c].z;
        if (!(s > options.deadChannelFraction * total) || !(total > 0.0)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}:{}: channel {} is dead: full drive gives X+Y+Z = "
                                         "{:.4g} cd/m^2 above black ({:.2g}% of the three "
                                         "primaries); check the cable and the panel",
                                         data.source, data.ramps[c].back().line, kChannelNames[c],
                                         s, total > 0.0 ? 100.0 * s / total : 0.0));
        }
    }
    const glm::dmat3 m0(primary[0], primary[1], primary[2]);
    const double normDet =
            std::abs(glm::determinant(m0)) /
            (glm::length(primary[0]) * glm::length(primary[1]) * glm::length(primary[2]));
    if (!(normDet > 1e-3)) {
        std::size_t a = 0;
        std::size_t b = 1;
        double best = -1.0;
        for (std::size_t i = 0; i < 3; ++i) {
            for (std::size_t j = i + 1; j < 3; ++j) {
                const double cosAngle =
                        std::abs(glm::dot(glm::normalize(primary[i]), glm::normalize(primary[j])));
                if (cosAngle > best) {
                    best = cosAngle;
                    a = i;
                    b = j;
                }
            }
        }
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the primaries matrix is singular (normalised "
                                     "determinant {:.2g}): channels {} and {} have nearly the same "
                                     "chromaticity; the ramps may be mislabelled",
                                     data.source, normDet, kChannelNames[a], kChannelNames[b]));
    }
    return m0;
}

// Monotonicity, judged on the direct-primaries derivation: small dips are meter noise and are
// pooled; a drop beyond the tolerance is a broken ramp. The tolerance grows with the noise the ramp
// itself shows (six sigma of a reading, from the median of its relative second differences, which
// dense levels leave to the noise): at 1 % noise dense ramps dip by more than 2 % between
// neighbouring levels.
Expected<void> checkMonotonic(const FitData& data, const FitOptions& options)
{
    const glm::dmat3 inv = glm::inverse(data.primaries);
    for (std::size_t c = 0; c < 3; ++c) {
        const auto& ramp = data.ramps[c];
        std::vector<double> rs;
        for (const auto& p : ramp) {
            rs.push_back((inv * (p.xyz - data.black))[static_cast<int>(c)]);
        }
        std::vector<double> second;
        for (std::size_t i = 1; i + 1 < rs.size(); ++i) {
            if (rs[i] > 0.1) {
                second.push_back(std::abs(rs[i + 1] - 2.0 * rs[i] + rs[i - 1]) / rs[i]);
            }
        }
        const double sigmaRel = 1.4826 * percentile(second, 0.5) / std::sqrt(6.0);
        double runMax = 0.0;
        double runMaxCount = 0.0;
        for (std::size_t i = 0; i < ramp.size(); ++i) {
            const auto& p = ramp[i];
            const double r = rs[i];
            const double tolerance = std::max(options.monotonicTolerance, 6.0 * sigmaRel * runMax);
            if (runMax - r > tolerance) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("{}:{}: channel {} response is not monotonic: "
                                             "r drops from {:.3f} at count {} to {:.3f} at "
                                             "count {} (more than {:.1f}% of full drive); a "
                                             "stuck or mis-ordered ramp?",
                                             data.source, p.line, kChannelNames[c], runMax,
                                             runMaxCount, r, p.count, 100.0 * tolerance));
            }
            if (r > runMax) {
                runMax = r;
                runMaxCount = p.count;
            }
        }
    }
    return {};
}

// Training and held-out colours: alternate off-ramp colours in file order. dE00 is judged against
// the white reading, or the primaries' sum where there is none.
Expected<void>
splitColours(const std::vector<Measurement>& rows, const FitOptions& options, FitData& data)
{
    if (static_cast<int>(data.colours.size()) < options.minColours) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: only {} measured colours off the single-channel ramps; "
                                     "the fit and its held-out check need at least {}",
                                     data.source, data.colours.size(), options.minColours));
    }
    for (std::size_t i = 0; i < data.colours.size(); ++i) {
        (i % 2 == 0 ? data.training : data.heldOut).push_back(data.colours[i]);
    }
    const auto whiteIt = std::find_if(rows.begin(), rows.end(), [&](const Measurement& m) {
        return m.counts == glm::dvec3(data.maxCount);
    });
    if (whiteIt != rows.end()) {
        data.white = whiteIt->xyz;
    }
    data.refWhite = data.white ? *data.white : data.black + data.primaries * glm::dvec3(1.0);
    return {};
}

// What the measurements give, checked: black, the ramps, the direct primaries, the colours.
Expected<FitData> readFitData(const MeasurementSet& set, const FitOptions& options)
{
    FitData data;
    data.source = set.source;
    data.maxCount = std::ldexp(1.0, set.bitDepth) - 1.0;
    std::vector<int> repeats;
    const auto rows = averageRepeats(set.rows, repeats);
    auto black = findBlack(rows, data.source);
    if (!black) {
        return tl::unexpected(black.error());
    }
    data.black = *black;
    if (auto ok = splitRamps(rows, repeats, options, data); !ok) {
        return tl::unexpected(ok.error());
    }
    auto primaries = directPrimaries(data, options);
    if (!primaries) {
        return tl::unexpected(primaries.error());
    }
    data.primaries = *primaries;
    if (auto ok = checkMonotonic(data, options); !ok) {
        return tl::unexpected(ok.error());
    }
    if (auto ok = splitColours(rows, options, data); !ok) {
        return tl::unexpected(ok.error());
    }
    return data;
}

// The chosen candidate as a model, normalised so that r runs from 0 at count 0 to 1 at full drive
// (forward unchanged). Adds the robust fit's monotone corrections to the candidate's.
Expected<DisplayModel> normalisedModel(Candidate& best,
                                       const FitData& data,
                                       const MeasurementSet& set,
                                       const FitOptions& options)
{
    DisplayModel model;
    model.name = options.name;
    model.description = options.description;
    model.synthetic = options.synthetic;
    model.bitDepth = set.bitDepth;
    model.condition = options.condition;
    glm::dvec3 lo{0.0};
    glm::dvec3 span{1.0};
    std::array<ToneCurve, 3> bestTone;
    for (std::size_t c = 0; c < 3; ++c) {
        if (best.robust) {
            int moved = 0;
            bestTone[c] = best.fits[c].curve(&moved);
            best.corrections += moved;
        } else {
            bestTone[c] = best.tone[c];
        }
    }
    for (std::size_t c = 0; c < 3; ++c) {
        const auto& v = bestTone[c].values();
        lo[static_cast<int>(c)] = v.front();
        span[static_cast<int>(c)] = v.back() - v.front();
        if (!(span[static_cast<int>(c)] > 0.0)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: channel {} has no response after fitting (flat "
                                         "ramp)",
                                         data.source, kChannelNames[c]));
        }
        std::vector<double> values(v.size());
        for (std::size_t i = 0; i < v.size(); ++i) {
            values[i] = (v[i] - v.front()) / span[static_cast<int>(c)];
        }
        values.front() = 0.0;
        values.back() = 1.0;
        model.tone[c] = ToneCurve(bestTone[c].counts(), std::move(values));
    }
    model.blackXyz = data.black + best.matrix * lo;
    model.matrix = best.matrix * glm::dmat3(glm::dvec3(span.x, 0, 0), glm::dvec3(0, span.y, 0),
                                            glm::dvec3(0, 0, span.z));
    if (model.blackXyz.x < 0.0 || model.blackXyz.y < 0.0 || model.blackXyz.z < 0.0) {
        model.blackXyz = glm::max(model.blackXyz, glm::dvec3(0.0));
    }
    return model;
}

// The model's accuracy on the training and held-out colours.
void reportAccuracy(const DisplayModel& model, const FitData& data, FitReport& report)
{
    auto errors = [&](const std::vector<Measurement>& s) {
        std::vector<double> e;
        for (const auto& m : s) {
            e.push_back(deltaE2000Xyz(model.forward(m.counts), m.xyz, data.refWhite));
        }
        return e;
    };
    const auto held = errors(data.heldOut);
    report.trainingColours = static_cast<int>(data.training.size());
    report.heldOutColours = static_cast<int>(data.heldOut.size());
    report.heldOutMeanDe00 = mean(held);
    report.heldOutP90De00 = percentile(held, 0.9);
    report.heldOutMaxDe00 = held.empty() ? 0.0 : *std::max_element(held.begin(), held.end());
    report.trainingMeanDe00 = mean(errors(data.training));
}

// The largest chromaticity drift of each primary along its ramp (readings above a tenth of full
// drive).
void reportChromaticityDrift(const FitData& data, FitReport& report)
{
    for (std::size_t c = 0; c < 3; ++c) {
        const glm::dvec3 primary = data.primaries[static_cast<int>(c)];
        const glm::dvec2 full = chromaticity(primary);
        double drift = 0.0;
        for (const auto& p : data.ramps[c]) {
            const glm::dvec3 above = p.xyz - data.black;
            if (above.y + above.x + above.z > 0.1 * (primary.x + primary.y + primary.z)) {
                drift = std::max(drift, glm::length(chromaticity(above) - full));
            }
        }
        report.chromaticityDrift[c] = drift;
    }
}

} // namespace

Expected<DisplayModel> fitDisplay(const MeasurementSet& set, const FitOptions& options)
{
    auto data = readFitData(set, options);
    if (!data) {
        return tl::unexpected(data.error());
    }
    const bool robust = options.toneMethod == ToneMethod::Robust;
    MatrixChoice choice = chooseMatrix(*data, options);
    FitReport report;
    report.directPrimariesHeldOutMeanDe00 = choice.directHeldOutMeanDe00;
    report.optimiserEvaluations = choice.optimiserEvaluations;
    auto model = normalisedModel(choice.best, *data, set, options);
    if (!model) {
        return model;
    }
    if (robust) {
        chooseCrosstalk(*model, data->colours, data->refWhite, report);
    }
    reportAccuracy(*model, *data, report);
    report.monotonicCorrections = choice.best.corrections;
    if (robust) {
        reportUncertainty(*model, *data, choice, set.rows, options.bootstrapReplicates, report);
    } else if (data->white) {
        // Additivity: the measured white against the sum of the measured primaries.
        const glm::dmat3& p = data->primaries;
        const glm::dvec3 sum = data->black + p[0] + p[1] + p[2];
        report.additivityDe00 = deltaE2000Xyz(*data->white, sum, data->refWhite);
        report.additivityLuminancePercent =
                sum.y > 0.0 ? 100.0 * (data->white->y - sum.y) / sum.y : 0.0;
    }
    reportChromaticityDrift(*data, report);
    for (std::size_t c = 0; c < 3; ++c) {
        report.rampLevels[c] = static_cast<int>(data->ramps[c].size());
        report.gogOnlyForShortRamps = report.gogOnlyForShortRamps ||
                                      (robust && report.rampLevels[c] < options.minRampLevels);
    }
    model->fit = report;
    if (auto ok = model->validate(); !ok) {
        return tl::unexpected(ok.error());
    }
    return model;
}

} // namespace replica::pipeline::display
