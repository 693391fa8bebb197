// Fitting, applying and storing the paper's six-channel representation.
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/output_file.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/csv/csv_cells.h>
#include <pipeline/spectral/dense_matrix.h>
#include <pipeline/spectral/fit_metric.h>
#include <pipeline/spectral/six_channel_model.h>

namespace replica::pipeline::spectral {
namespace {

using colour::kBands;
using colour::kChannels;
constexpr std::size_t kK = kChannels;

class SixChannelRepresentation final : public Representation
{
public:
    SixChannelRepresentation(const Observer& obs, SixChannelModel model)
        : obs_(obs), model_(std::move(model))
    {}
    std::string name() const override { return model_.name; }
    std::size_t channels() const override { return kK; }
    std::vector<double> encode(const Spectrum& reflectance) const override
    {
        std::vector<double> c(kK);
        for (std::size_t k = 0; k < kK; ++k) {
            c[k] = (model_.reflectProject[k] * reflectance).sum();
        }
        return c;
    }
    std::vector<Xyz> lightVectors(const Spectrum& light) const override
    {
        const auto m = sixChannelToXyz(model_, obs_, light);
        return {m.begin(), m.end()};
    }

private:
    Observer obs_;
    SixChannelModel model_;
};

Expected<DenseMatrix> solveRidge(DenseMatrix n, const DenseMatrix& rhs, double ridge)
{
    double trace = 0.0;
    for (std::size_t i = 0; i < n.rows(); ++i) {
        trace += n(i, i);
    }
    const double add = ridge * trace / static_cast<double>(n.rows()) + 1e-300;
    for (std::size_t i = 0; i < n.rows(); ++i) {
        n(i, i) += add;
    }
    return solve(n, rhs);
}

} // namespace

colour::ChannelToXyz
sixChannelToXyz(const SixChannelModel& model, const Observer& obs, const Spectrum& light)
{
    colour::ChannelToXyz m{};
    const double y = colour::spectrumToXyz(obs, light).y;
    if (!(y > 0.0)) {
        return m;
    }
    for (std::size_t k = 0; k < kK; ++k) {
        const double s = (model.lightProject[k] * light).sum() / y;
        m[k] = model.toXyz[k] * s;
    }
    return m;
}

std::unique_ptr<Representation> makeSixChannelRepresentation(const Observer& obs,
                                                             SixChannelModel model)
{
    return std::make_unique<SixChannelRepresentation>(obs, std::move(model));
}

namespace {

// The alternating least squares of the six-channel fit: with two of the toXyz matrix T, the
// reflectance projection P_r and the light projection P_l fixed, the third minimises the weighted
// squared XYZ error over the training lights and reflectances in closed form (a ridge-regularised
// linear solve).
class SixChannelAls
{
public:
    SixChannelAls(std::vector<FitLight> fitLights,
                  DenseMatrix c,
                  const colour::ChannelBasis& initial)
        : fitLights_(std::move(fitLights)), c_(std::move(c)), nl_(fitLights_.size()), g_(nl_),
          u_(nl_), hg_(nl_), hgc_(nl_), pl_(kK, kBands), pr_(kK, kBands), t_(kK, 3)
    {
        for (std::size_t j = 0; j < nl_; ++j) {
            g_[j] = fitLights_[j].h * fitLights_[j].a;
            u_[j] = fitLights_[j].h.transposed() * fitLights_[j].h;
            hg_[j] = fitLights_[j].h.transposed() * g_[j];
            hgc_[j] = hg_[j] * c_;
        }
        for (std::size_t k = 0; k < kK; ++k) {
            for (std::size_t l = 0; l < kBands; ++l) {
                pr_(k, l) = initial.project[k][l];
                pl_(k, l) = initial.project[k][l];
            }
        }
    }

    // Step 1: toXyz.
    Expected<void> solveToXyz()
    {
        const DenseMatrix x = c_ * pr_.transposed(); // 36 x K: sum_i w^2 r_i c_i^T / N
        const DenseMatrix cc = pr_ * x;              // K x K
        DenseMatrix n(3 * kK, 3 * kK), rhs(3 * kK, 1);
        for (std::size_t j = 0; j < nl_; ++j) {
            const auto s = lightCoeffs(j);
            const DenseMatrix hgx = hg_[j] * x; // 3 x K
            for (std::size_t k = 0; k < kK; ++k) {
                for (std::size_t a = 0; a < 3; ++a) {
                    rhs(3 * k + a, 0) += s[k] * hgx(a, k);
                    for (std::size_t k2 = 0; k2 < kK; ++k2) {
                        for (std::size_t b = 0; b < 3; ++b) {
                            n(3 * k + a, 3 * k2 + b) += s[k] * s[k2] * u_[j](a, b) * cc(k, k2);
                        }
                    }
                }
            }
        }
        auto sol = solveRidge(n, rhs, kRidge);
        if (!sol) {
            return tl::unexpected(sol.error());
        }
        for (std::size_t k = 0; k < kK; ++k) {
            for (std::size_t a = 0; a < 3; ++a) {
                t_(k, a) = (*sol)(3 * k + a, 0);
            }
        }
        return {};
    }

    // Step 2: reflectProject.
    Expected<void> solveReflectProject()
    {
        DenseMatrix sum(kK, kK);
        DenseMatrix rhs(kK * kBands, 1);
        for (std::size_t j = 0; j < nl_; ++j) {
            const auto s = lightCoeffs(j);
            const DenseMatrix q = tut(j);
            const DenseMatrix thgc = t_ * hgc_[j]; // K x 36
            for (std::size_t k = 0; k < kK; ++k) {
                for (std::size_t k2 = 0; k2 < kK; ++k2) {
                    sum(k, k2) += s[k] * s[k2] * q(k, k2);
                }
                for (std::size_t l = 0; l < kBands; ++l) {
                    rhs(k * kBands + l, 0) += s[k] * thgc(k, l);
                }
            }
        }
        DenseMatrix n(kK * kBands, kK * kBands);
        for (std::size_t k = 0; k < kK; ++k) {
            for (std::size_t k2 = 0; k2 < kK; ++k2) {
                for (std::size_t l = 0; l < kBands; ++l) {
                    for (std::size_t l2 = 0; l2 < kBands; ++l2) {
                        n(k * kBands + l, k2 * kBands + l2) = sum(k, k2) * c_(l, l2);
                    }
                }
            }
        }
        auto sol = solveRidge(n, rhs, kRidge);
        if (!sol) {
            return tl::unexpected(sol.error());
        }
        for (std::size_t k = 0; k < kK; ++k) {
            for (std::size_t l = 0; l < kBands; ++l) {
                pr_(k, l) = (*sol)(k * kBands + l, 0);
            }
        }
        return {};
    }

    // Step 3: lightProject.
    Expected<void> solveLightProject()
    {
        const DenseMatrix x2 = c_ * pr_.transposed();
        const DenseMatrix cc2 = pr_ * x2;
        DenseMatrix n(kK * kBands, kK * kBands), rhs(kK * kBands, 1);
        for (std::size_t j = 0; j < nl_; ++j) {
            const DenseMatrix q = tut(j);
            const DenseMatrix thgx = t_ * (hg_[j] * x2); // K x K; diagonal (k, k) is what we need
            const Spectrum& e = fitLights_[j].spectrum;
            for (std::size_t k = 0; k < kK; ++k) {
                for (std::size_t l = 0; l < kBands; ++l) {
                    rhs(k * kBands + l, 0) += e[l] * thgx(k, k);
                }
                for (std::size_t k2 = 0; k2 < kK; ++k2) {
                    const double f = q(k, k2) * cc2(k, k2);
                    for (std::size_t l = 0; l < kBands; ++l) {
                        for (std::size_t l2 = 0; l2 < kBands; ++l2) {
                            n(k * kBands + l, k2 * kBands + l2) += f * e[l] * e[l2];
                        }
                    }
                }
            }
        }
        auto sol = solveRidge(n, rhs, kRidge);
        if (!sol) {
            return tl::unexpected(sol.error());
        }
        for (std::size_t k = 0; k < kK; ++k) {
            for (std::size_t l = 0; l < kBands; ++l) {
                pl_(k, l) = (*sol)(k * kBands + l, 0);
            }
        }
        return {};
    }

    // The weighted squared XYZ error the steps minimise.
    double objective() const
    {
        const DenseMatrix x3 = c_ * pr_.transposed();
        const DenseMatrix cc3 = pr_ * x3;
        double obj = 0.0;
        for (std::size_t j = 0; j < nl_; ++j) {
            const auto s = lightCoeffs(j);
            const DenseMatrix gcg = g_[j] * c_ * g_[j].transposed();
            obj += gcg(0, 0) + gcg(1, 1) + gcg(2, 2);
            const DenseMatrix thgx = t_ * (hg_[j] * x3);
            const DenseMatrix q = tut(j);
            for (std::size_t k = 0; k < kK; ++k) {
                obj -= 2.0 * s[k] * thgx(k, k);
                for (std::size_t k2 = 0; k2 < kK; ++k2) {
                    obj += s[k] * s[k2] * q(k, k2) * cc3(k, k2);
                }
            }
        }
        return obj;
    }

    // Gauge: the product s_k c_k T_k is unchanged by scaling lightProject[k] by a and toXyz[k] by
    // 1/a; choose a so that an equal-energy light has s_k = 1, which keeps the light channels
    // readable.
    SixChannelModel gaugedModel(const Observer& obs, const std::string& name) const
    {
        SixChannelModel model;
        model.name = name;
        const Spectrum equal =
                Spectrum::constant(1.0 / colour::spectrumToXyz(obs, Spectrum::constant(1.0)).y);
        for (std::size_t k = 0; k < kK; ++k) {
            double s = 0.0;
            for (std::size_t l = 0; l < kBands; ++l) {
                s += pl_(k, l) * equal[l];
            }
            const double a = std::abs(s) > 1e-12 ? 1.0 / s : 1.0;
            for (std::size_t l = 0; l < kBands; ++l) {
                model.lightProject[k][l] = pl_(k, l) * a;
                model.reflectProject[k][l] = pr_(k, l);
            }
            model.toXyz[k] = Xyz{t_(k, 0), t_(k, 1), t_(k, 2)} * (1.0 / a);
        }
        return model;
    }

private:
    std::array<double, kK> lightCoeffs(std::size_t j) const
    {
        std::array<double, kK> s{};
        for (std::size_t k = 0; k < kK; ++k) {
            for (std::size_t l = 0; l < kBands; ++l) {
                s[k] += pl_(k, l) * fitLights_[j].spectrum[l];
            }
        }
        return s;
    }

    // T_k^T U_j T_k' for all k, k'.
    DenseMatrix tut(std::size_t j) const
    {
        const DenseMatrix ut = u_[j] * t_.transposed(); // 3 x K
        return t_ * ut;                                 // K x K
    }

    static constexpr double kRidge = 1e-9;
    std::vector<FitLight> fitLights_;
    DenseMatrix c_;
    std::size_t nl_;
    std::vector<DenseMatrix> g_, u_, hg_, hgc_; // G_j = H_j A_j, U_j = H^T H, H^T G, H^T G C
    DenseMatrix pl_, pr_, t_;
};

} // namespace

Expected<SixChannelModel> fitSixChannelModel(const Observer& obs,
                                             const Spectrum& d65,
                                             const NamedSpectra& reflectances,
                                             const NamedSpectra& lights,
                                             const colour::ChannelBasis& initial,
                                             int rounds,
                                             const std::string& name,
                                             SixChannelFitReport* report)
{
    const auto fitLights = makeFitLights(obs, d65, lights, true);
    if (fitLights.empty() || reflectances.size() < kK) {
        return makeError(ErrorCode::InvalidArgument, "six-channel fit: needs training lights with "
                                                     "luminance and at least six reflectances");
    }
    SixChannelAls als(fitLights,
                      weightedSecondMoment(reflectances, sampleWeights(obs, reflectances, true)),
                      initial);
    for (int round = 0; round < rounds; ++round) {
        for (auto step : {&SixChannelAls::solveToXyz, &SixChannelAls::solveReflectProject,
                          &SixChannelAls::solveLightProject}) {
            if (auto ok = (als.*step)(); !ok) {
                return tl::unexpected(ok.error());
            }
        }
        if (report != nullptr) {
            report->objective.push_back(als.objective());
        }
    }
    return als.gaugedModel(obs, name);
}

} // namespace replica::pipeline::spectral

namespace replica::pipeline::spectral {
namespace {

std::filesystem::path toXyzPath(const std::filesystem::path& csvPath)
{
    auto p = csvPath;
    p.replace_filename(csvPath.stem().string() + "_to_xyz.csv");
    return p;
}

} // namespace

Expected<SixChannelModel> loadSixChannelModel(const std::filesystem::path& csvPath)
{
    auto table = colour::loadSpectralCsv(csvPath);
    if (!table) {
        return tl::unexpected(table.error());
    }
    auto grid = colour::checkWorkingGrid(*table);
    if (!grid) {
        return tl::unexpected(grid.error());
    }
    SixChannelModel model;
    model.name = csvPath.stem().string();
    for (std::size_t k = 0; k < kK; ++k) {
        auto l = colour::workingGridColumn(*table, fmt::format("light_{}", k + 1));
        auto r = colour::workingGridColumn(*table, fmt::format("reflectance_{}", k + 1));
        if (!l || !r) {
            return tl::unexpected(!l ? l.error() : r.error());
        }
        model.lightProject[k] = *l;
        model.reflectProject[k] = *r;
    }
    const auto xyzPath = toXyzPath(csvPath);
    // Through the bounded reader: a regular file of at most kMaxCsvBytes (a FIFO, /dev/zero or a
    // directory in its place is refused in one line).
    auto xyzText = readInputFile(xyzPath, kMaxCsvBytes, "six-channel [6 x 3] matrix");
    if (!xyzText) {
        if (xyzText.error().code != ErrorCode::NotFound) {
            return tl::unexpected(xyzText.error());
        }
        return makeError(
                ErrorCode::NotFound,
                fmt::format("{}: cannot open the six-channel [6 x 3] matrix (it belongs beside {})",
                            xyzPath.string(), csvPath.filename().string()));
    }
    std::istringstream file(*xyzText);
    std::string line;
    int lineNo = 0;
    std::size_t rows = 0;
    bool header = false;
    while (std::getline(file, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') {
            line.pop_back();
        }
        if (line.empty() || line[0] == '#') {
            continue;
        }
        if (!header) {
            if (line != "channel,X,Y,Z") {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("{}:{}: header must be 'channel,X,Y,Z'",
                                             xyzPath.string(), lineNo));
            }
            header = true;
            continue;
        }
        const std::vector<std::string> cells = csv::splitCsvRow(line);
        double v[4] = {};
        if (cells.size() != 4) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}:{}: {} cells, expected 4 (channel,X,Y,Z)",
                                         xyzPath.string(), lineNo, cells.size()));
        }
        for (std::size_t i = 0; i < 4; ++i) {
            if (!csv::parseFiniteNumber(cells[i], v[i])) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("{}:{}: '{}' is not a finite number", xyzPath.string(),
                                             lineNo, csv::shownCell(cells[i])));
            }
        }
        if (v[0] != static_cast<double>(rows + 1) || rows >= kK) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}:{}: expected channel {}", xyzPath.string(), lineNo, rows + 1));
        }
        model.toXyz[rows++] = Xyz{v[1], v[2], v[3]};
    }
    if (rows != kK) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("{}: has {} channel rows, expected {}", xyzPath.string(), rows, kK));
    }
    return model;
}

Expected<void> saveSixChannelModel(const SixChannelModel& model,
                                   const std::filesystem::path& csvPath,
                                   const std::string& provenance)
{
    std::string text =
            fmt::format("# Replica six-channel model '{}' (paper representation 2): {}\n",
                        model.name, provenance);
    text += "wavelength_nm";
    for (std::size_t k = 0; k < kK; ++k) {
        text += fmt::format(",light_{}", k + 1);
    }
    for (std::size_t k = 0; k < kK; ++k) {
        text += fmt::format(",reflectance_{}", k + 1);
    }
    text += "\n";
    for (std::size_t l = 0; l < kBands; ++l) {
        text += fmt::format("{}", colour::bandCentreNm(l));
        for (std::size_t k = 0; k < kK; ++k) {
            text += fmt::format(",{:.17g}", model.lightProject[k][l]);
        }
        for (std::size_t k = 0; k < kK; ++k) {
            text += fmt::format(",{:.17g}", model.reflectProject[k][l]);
        }
        text += "\n";
    }
    std::string xyz =
            fmt::format("# [6 x 3] channel-to-XYZ matrix of '{}'\nchannel,X,Y,Z\n", model.name);
    for (std::size_t k = 0; k < kK; ++k) {
        xyz += fmt::format("{},{:.17g},{:.17g},{:.17g}\n", k + 1, model.toXyz[k].x,
                           model.toXyz[k].y, model.toXyz[k].z);
    }
    for (const auto& [path, body] :
         {std::pair{csvPath, text}, std::pair{toXyzPath(csvPath), xyz}}) {
        if (auto ok = writeOutputFile(path, body, "six-channel model"); !ok) {
            return ok;
        }
    }
    return {};
}

} // namespace replica::pipeline::spectral
