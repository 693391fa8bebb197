// The display fit's crosstalk candidates.
#include <array>
#include <cmath>
#include <numeric>
#include <utility>

#include <pipeline/base/linear_solve.h>
#include <pipeline/display/xyz_difference.h>
#include <pipeline/offline/display/display_crosstalk_fit.h>

namespace replica::pipeline::display {
namespace {

// The crosstalk families, nested: "uniform" (C = c J, J all ones: each pair's product adds light
// in the additive white's colour, c < 0 a loss, one parameter) and "full" (each entry free, nine).
enum class CrosstalkFamily { Uniform, Full };

glm::dmat3 crosstalkBasis(CrosstalkFamily family, int k)
{
    if (family == CrosstalkFamily::Uniform) {
        return glm::dmat3(glm::dvec3(1.0), glm::dvec3(1.0), glm::dvec3(1.0));
    }
    glm::dmat3 b(0.0);
    b[k / 3][k % 3] = 1.0;
    return b;
}

// The crosstalk C of 'family' that fits the colours' residuals from the additive 'model' by
// least squares in XYZ, each component weighted by 1 / (its reading + 0.1 % of white's)^2 (the
// meter's noise is relative, with a floor). Zero when the system is singular or C leaves the
// profile's bound.
glm::dmat3 fitCrosstalkTerm(const DisplayModel& model,
                            const std::vector<Measurement>& colours,
                            CrosstalkFamily family)
{
    const int n = family == CrosstalkFamily::Uniform ? 1 : 9;
    std::array<std::array<double, 10>, 9> a{}; // normal equations, augmented
    const glm::dvec3 white = model.whiteXyz();
    for (const auto& m : colours) {
        const glm::dvec3 r = model.linearFromCounts(m.counts);
        const glm::dvec3 p = crosstalkProducts(r);
        const glm::dvec3 d = m.xyz - (model.blackXyz + model.matrix * r);
        std::array<glm::dvec3, 9> col{};
        for (int k = 0; k < n; ++k) {
            col[static_cast<std::size_t>(k)] = model.matrix * (crosstalkBasis(family, k) * p);
        }
        for (int q = 0; q < 3; ++q) {
            const double sigma = std::abs(m.xyz[q]) + 1e-3 * std::abs(white[q]);
            const double w = sigma > 0.0 ? 1.0 / (sigma * sigma) : 0.0;
            for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
                for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) {
                    a[i][j] += w * col[i][q] * col[j][q];
                }
                a[i][static_cast<std::size_t>(n)] += w * col[i][q] * d[q];
            }
        }
    }
    // The normal equations, singular when a pivot falls below 1e-12 of the largest diagonal.
    const auto nn = static_cast<std::size_t>(n);
    std::vector<double> lhs(nn * nn);
    std::vector<double> coef(nn);
    double scale = 0.0;
    for (std::size_t i = 0; i < nn; ++i) {
        for (std::size_t j = 0; j < nn; ++j) {
            lhs[i * nn + j] = a[i][j];
        }
        coef[i] = a[i][nn];
        scale = std::max(scale, std::abs(a[i][i]));
    }
    if (!solveLinear(lhs, coef, nn, 1e-12 * scale)) {
        return glm::dmat3(0.0);
    }
    glm::dmat3 c(0.0);
    for (std::size_t k = 0; k < nn; ++k) {
        c += coef[k] * crosstalkBasis(family, static_cast<int>(k));
    }
    DisplayModel check = model;
    check.crosstalk = c;
    if (!check.validate()) {
        return glm::dmat3(0.0);
    }
    return c;
}

// The one-parameter crosstalk's coefficient over its standard error: the weighted least-squares
// fit of fitCrosstalkTerm's uniform family, its error from the weighted residuals (their scatter
// is the meter's relative noise plus what the additive model misses, so a poor tone fit makes the
// test stricter, not looser). Zero when there is nothing to fit.
double uniformCrosstalkZ(const DisplayModel& model, const std::vector<Measurement>& colours)
{
    const glm::dvec3 white = model.whiteXyz();
    const glm::dmat3 basis = crosstalkBasis(CrosstalkFamily::Uniform, 0);
    struct Row {
        glm::dvec3 d;
        glm::dvec3 col;
        glm::dvec3 w;
    };
    std::vector<Row> rows;
    double a = 0.0;
    double b = 0.0;
    for (const auto& m : colours) {
        const glm::dvec3 r = model.linearFromCounts(m.counts);
        Row row{m.xyz - (model.blackXyz + model.matrix * r),
                model.matrix * (basis * crosstalkProducts(r)), glm::dvec3(0.0)};
        for (int q = 0; q < 3; ++q) {
            const double sigma = std::abs(m.xyz[q]) + 1e-3 * std::abs(white[q]);
            row.w[q] = sigma > 0.0 ? 1.0 / (sigma * sigma) : 0.0;
            a += row.w[q] * row.col[q] * row.col[q];
            b += row.w[q] * row.col[q] * row.d[q];
        }
        rows.push_back(row);
    }
    const double dof = 3.0 * static_cast<double>(rows.size()) - 1.0;
    if (!(a > 0.0) || !(dof > 0.0)) {
        return 0.0;
    }
    const double c = b / a;
    double chi2 = 0.0;
    for (const auto& row : rows) {
        for (int q = 0; q < 3; ++q) {
            const double e = row.d[q] - c * row.col[q];
            chi2 += row.w[q] * e * e;
        }
    }
    const double var = chi2 / dof / a;
    return var > 0.0 ? std::abs(c) / std::sqrt(var) : 0.0;
}

// Paired held-out gain in dE00 of 'family' over 'base' (C = baseC): k-fold cross-validation over
// 'colours'. Returns the mean gain and its standard error.
std::pair<double, double> crosstalkGain(const DisplayModel& model,
                                        const std::vector<Measurement>& colours,
                                        CrosstalkFamily family,
                                        const std::vector<glm::dmat3>& baseFolds,
                                        std::vector<glm::dmat3>* folds,
                                        const glm::dvec3& refWhite)
{
    constexpr std::size_t kFolds = 5;
    std::vector<double> gain;
    for (std::size_t f = 0; f < kFolds; ++f) {
        std::vector<Measurement> train;
        std::vector<Measurement> test;
        for (std::size_t i = 0; i < colours.size(); ++i) {
            (i % kFolds == f ? test : train).push_back(colours[i]);
        }
        DisplayModel fitted = model;
        fitted.crosstalk = fitCrosstalkTerm(model, train, family);
        folds->push_back(fitted.crosstalk);
        DisplayModel base = model;
        base.crosstalk = baseFolds.empty() ? glm::dmat3(0.0) : baseFolds[f];
        for (const auto& m : test) {
            gain.push_back(deltaE2000Xyz(base.forward(m.counts), m.xyz, refWhite) -
                           deltaE2000Xyz(fitted.forward(m.counts), m.xyz, refWhite));
        }
    }
    if (gain.size() < 2) {
        return {0.0, 0.0};
    }
    const double g =
            std::accumulate(gain.begin(), gain.end(), 0.0) / static_cast<double>(gain.size());
    double var = 0.0;
    for (double x : gain) {
        var += (x - g) * (x - g);
    }
    const double nGain = static_cast<double>(gain.size());
    return {g, std::sqrt(var / (nGain - 1.0) / nGain)};
}

} // namespace

void chooseCrosstalk(DisplayModel& model,
                     const std::vector<Measurement>& colours,
                     const glm::dvec3& refWhite,
                     FitReport& report)
{
    auto accept = [](const std::pair<double, double>& g) {
        return g.first > 2.0 * g.second && g.first > 1e-3;
    };
    std::vector<glm::dmat3> uniformFolds;
    std::vector<glm::dmat3> fullFolds;
    const auto uniformGain =
            crosstalkGain(model, colours, CrosstalkFamily::Uniform, {}, &uniformFolds, refWhite);
    const auto fullGain =
            crosstalkGain(model, colours, CrosstalkFamily::Full, {}, &fullFolds, refWhite);
    const double z = uniformCrosstalkZ(model, colours);
    report.crosstalkZ = z;
    const bool uniformOk = z > 3.0 && uniformGain.first > 1e-3;
    bool fullOk = accept(fullGain);
    if (fullOk && uniformOk) {
        std::vector<glm::dmat3> unused;
        fullOk = accept(crosstalkGain(model, colours, CrosstalkFamily::Full, uniformFolds, &unused,
                                      refWhite));
    }
    if (fullOk) {
        model.crosstalk = fitCrosstalkTerm(model, colours, CrosstalkFamily::Full);
        report.crosstalkModel = "full";
    } else if (uniformOk) {
        model.crosstalk = fitCrosstalkTerm(model, colours, CrosstalkFamily::Uniform);
        report.crosstalkModel = "uniform";
    } else {
        report.crosstalkModel = "none";
    }
    report.crosstalkGainDe00 = fullOk ? fullGain.first : uniformGain.first;
    if (!model.hasCrosstalk()) {
        report.crosstalkModel = "none";
    }
}

} // namespace replica::pipeline::display
