// Calibrates the planner's cost model (pipeline/tuning/planner.cpp, settingCost) to the GL frame:
// for every shipped scene a grid of the settings the planner chooses between (median-cut lights;
// specular samples on glossy scenes; horizon directions on scenes with relief) is built into an
// appliance ('replica run' defaults otherwise, adaptive_k6, 960x600) and its whole frame (both
// passes, display read-back) timed as the median of N frames with the tilt moving a degree a frame
// (pass 1 recomputing its diffuse term in bands: the frame the loop's deadline must hold while the
// panel moves) and with the eye moving (pass 1 from its cache). Then, per scene class, the least
// squares fit of the tilt-moving CPU-time median (every llvmpipe thread; steadier than the wall
// clock on a shared machine) to t0 + L * lights + H * horizon directions + S * specular samples,
// printed with each setting's measured and predicted time, R^2 and the residuals' RMS. The booth's
// walls (RenderSettings::walls, a constant the planner adds) are timed apart: one setting in the
// middle of the grid under the shipped booth and under a copy that declares N7 walls, alternated
// in pairs, the median of the pairs' differences. The coefficients go into settingCost
// (docs/rendering.md, "Planner"); run this again to refit after a renderer change.
// Usage: replica_bench_cost_model [--frames N] [--size WxH] [--scene NAME]
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <tests/benchmarks/frame_bench_args.h>
#include <tests/benchmarks/frame_timing.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/tuning/planner.h>
#include <platform/appliance.h>

using namespace replica;
using namespace replica::pipeline;

namespace {

struct Row {
    int lights = 0;
    int samples = 0;
    int dirs = 0;
    double tiltCpu = 0.0;
    double tiltWall = 0.0;
    double eyeCpu = 0.0;
    double eyeWall = 0.0;
    double modelCost = 0.0; // settingCost as built
};

bool timeSetting(const std::string& scene,
                 Row& r,
                 int frames,
                 int w,
                 int h,
                 const std::string& boothDir = "booth")
{
    platform::RunConfig c;
    c.width = w;
    c.height = h;
    c.sceneDir = "scenes/" + scene;
    c.boothDir = boothDir;
    c.boothLights = r.lights;
    c.specularSamples = r.samples > 0 ? r.samples : platform::kAutoSpecularSamples;
    c.horizonDirections = r.dirs > 0 ? r.dirs : c.horizonDirections;
    auto app = platform::buildAppliance(c);
    if (!app) {
        std::fprintf(stderr, "appliance: %s\n", app.error().message.c_str());
        return false;
    }
    bench::FrameTimes eye, tilt;
    if (!bench::timeFrames(**app, 0, frames, eye, tilt)) {
        return false;
    }
    r.eyeWall = eye.wall.median;
    r.eyeCpu = eye.cpu.median;
    r.tiltWall = tilt.wall.median;
    r.tiltCpu = tilt.cpu.median;
    return true;
}

// Least squares of y on the columns of x (normal equations, Gaussian elimination with partial
// pivoting); false when singular.
bool leastSquares(const std::vector<std::vector<double>>& x,
                  const std::vector<double>& y,
                  std::vector<double>& beta)
{
    const std::size_t n = x.front().size();
    std::vector<std::vector<double>> a(n, std::vector<double>(n + 1, 0.0));
    for (std::size_t r = 0; r < x.size(); ++r) {
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = 0; j < n; ++j) {
                a[i][j] += x[r][i] * x[r][j];
            }
            a[i][n] += x[r][i] * y[r];
        }
    }
    for (std::size_t c = 0; c < n; ++c) {
        std::size_t p = c;
        for (std::size_t r = c + 1; r < n; ++r) {
            if (std::abs(a[r][c]) > std::abs(a[p][c])) {
                p = r;
            }
        }
        if (std::abs(a[p][c]) < 1e-12) {
            return false;
        }
        std::swap(a[c], a[p]);
        for (std::size_t r = 0; r < n; ++r) {
            if (r != c) {
                const double f = a[r][c] / a[c][c];
                for (std::size_t k = c; k <= n; ++k) {
                    a[r][k] -= f * a[c][k];
                }
            }
        }
    }
    beta.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        beta[i] = a[i][n] / a[i][i];
    }
    return true;
}

// The shipped booth copied to 'dir' with "walls": {} (Munsell N7) added; false when it cannot be.
bool writeWalledBooth(const std::filesystem::path& dir)
{
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
    std::filesystem::copy(dataDir() / "booth", dir, std::filesystem::copy_options::recursive, ec);
    std::ifstream in(dir / "booth.json");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto end = text.rfind('}');
    if (ec || end == std::string::npos) {
        std::fprintf(stderr, "cannot copy the booth to %s\n", dir.string().c_str());
        return false;
    }
    text = text.substr(0, end) + ",\n  \"walls\": {}\n}\n";
    std::ofstream(dir / "booth.json") << text;
    auto walled = booth::loadBooth(dir);
    if (!walled || !walled->walls) {
        std::fprintf(stderr, "%s: the copy does not declare walls\n", dir.string().c_str());
        return false;
    }
    return true;
}

// The walls' cost: 'pairs' frames series of the same setting without and with the walls,
// alternated; prints each pair's difference of the tilt-moving CPU median and their median.
bool timeWalls(const std::string& scene,
               Row base,
               const std::string& walledBooth,
               int frames,
               int w,
               int h,
               int pairs)
{
    std::vector<double> diffs;
    for (int p = 0; p < pairs; ++p) {
        Row off = base;
        Row on = base;
        if (!timeSetting(scene, off, frames, w, h) ||
            !timeSetting(scene, on, frames, w, h, walledBooth)) {
            return false;
        }
        std::printf("%s walls, lights %d samples %d dirs %d: without %.1f with %.1f (tilt cpu)\n",
                    scene.c_str(), base.lights, base.samples, base.dirs, off.tiltCpu, on.tiltCpu);
        std::fflush(stdout);
        diffs.push_back(on.tiltCpu - off.tiltCpu);
    }
    std::printf("%s walls (N7): %+.2f ms, median of %d pairs (", scene.c_str(),
                bench::summarise(diffs).median, pairs);
    for (std::size_t i = 0; i < diffs.size(); ++i) {
        std::printf("%s%+.1f", i ? ", " : "", diffs[i]);
    }
    std::printf(")\n\n");
    return true;
}

// The grid of settings the planner chooses between on this scene, each timed.
bool timeGrid(const std::string& scene,
              bool glossy,
              bool relief,
              int specularGrid,
              int diffuseGrid,
              int frames,
              int w,
              int h,
              std::vector<Row>& rows)
{
    const std::vector<int> lights =
            glossy ? std::vector<int>{8, 32, 128} : std::vector<int>{8, 16, 32, 64, 128};
    for (const int l : lights) {
        for (const int s : glossy ? std::vector<int>{4, 16, 48} : std::vector<int>{0}) {
            for (const int d : relief ? std::vector<int>{8, 16} : std::vector<int>{0}) {
                Row r;
                r.lights = l;
                r.samples = s;
                r.dirs = d;
                shading::RenderSettings rs;
                rs.lights = l;
                rs.specularSamples = s;
                rs.horizonDirections = d;
                // The appliance's grids for the scene, which the frame timed draws with.
                rs.specularGrid = specularGrid;
                rs.diffuseGrid = diffuseGrid;
                r.modelCost = shading::settingCost(rs, glossy, relief);
                if (!timeSetting(scene, r, frames, w, h)) {
                    return false;
                }
                std::printf("%s lights %d samples %d dirs %d: tilt cpu %.1f wall %.1f, eye cpu "
                            "%.1f wall %.1f, cost model %.1f\n",
                            scene.c_str(), l, s, d, r.tiltCpu, r.tiltWall, r.eyeCpu, r.eyeWall,
                            r.modelCost);
                std::fflush(stdout);
                rows.push_back(r);
            }
        }
    }
    return true;
}

// t0 + L lights + H dirs + S samples (the columns the scene varies) fitted to the rows' tilt-moving
// CPU medians and printed: coefficients, R^2, residuals' RMS, and each row measured against fitted.
bool printFit(const std::string& scene, const std::vector<Row>& rows, bool glossy, bool relief)
{
    std::vector<std::vector<double>> x;
    std::vector<double> y;
    for (const Row& r : rows) {
        std::vector<double> cols{1.0, static_cast<double>(r.lights)};
        if (relief) {
            cols.push_back(r.dirs);
        }
        if (glossy) {
            cols.push_back(r.samples);
        }
        x.push_back(cols);
        y.push_back(r.tiltCpu);
    }
    std::vector<double> beta;
    if (!leastSquares(x, y, beta)) {
        std::fprintf(stderr, "%s: the fit is singular\n", scene.c_str());
        return false;
    }
    std::vector<double> fitted(rows.size(), 0.0);
    double mean = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        for (std::size_t k = 0; k < beta.size(); ++k) {
            fitted[i] += beta[k] * x[i][k];
        }
        mean += y[i] / static_cast<double>(rows.size());
    }
    double ssRes = 0.0;
    double ssTot = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        ssRes += (y[i] - fitted[i]) * (y[i] - fitted[i]);
        ssTot += (y[i] - mean) * (y[i] - mean);
    }
    const double perLight = beta[1];
    const double perDir = relief ? beta[2] : 0.0;
    const double perSample = glossy ? beta[relief ? 3 : 2] : 0.0;
    std::printf("\n%s fit (tilt-moving CPU ms): t0 %.2f + %.4f/light + %.4f/horizon direction + "
                "%.4f/specular sample; in light units: direction %.3f, sample %.3f; R^2 %.3f, "
                "residual RMS %.2f ms\n",
                scene.c_str(), beta[0], perLight, perDir, perSample,
                perLight > 0 ? perDir / perLight : 0.0, perLight > 0 ? perSample / perLight : 0.0,
                ssTot > 0 ? 1.0 - ssRes / ssTot : 0.0,
                std::sqrt(ssRes / static_cast<double>(rows.size())));
    std::printf("| lights | samples | dirs | measured ms | fitted ms | settingCost |\n"
                "|---|---|---|---|---|---|\n");
    for (std::size_t i = 0; i < rows.size(); ++i) {
        std::printf("| %d | %d | %d | %.1f | %.1f | %.1f |\n", rows[i].lights, rows[i].samples,
                    rows[i].dirs, rows[i].tiltCpu, fitted[i], rows[i].modelCost);
    }
    std::printf("\n");
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    replica::bench::FrameBenchArgs args;
    args.frames = 9;
    if (auto stop = replica::bench::parseFrameBenchArgs(
                argc, argv, args, 3,
                "Times the appliance's frame over a grid of planner settings on every shipped "
                "scene and fits the planner's cost model to it; then the booth's walls.")) {
        return *stop;
    }
    std::printf("%dx%d, median of %d frames; ms\n", args.width, args.height, args.frames);
    const auto walled = std::filesystem::temp_directory_path() / "replica-cost-model-walled-booth";
    if (!writeWalledBooth(walled)) {
        return 1;
    }
    for (const char* sceneName : {"metamer", "colorchecker", "painting", "glossy-cylinder"}) {
        if (!args.scene.empty() && args.scene != sceneName) {
            continue;
        }
        auto scene = surface::loadScene(dataDir() / "scenes" / sceneName);
        if (!scene) {
            std::fprintf(stderr, "%s\n", scene.error().message.c_str());
            return 1;
        }
        const bool glossy = scene->glossy();
        const bool relief = !scene->flat();
        std::vector<Row> rows;
        if (!timeGrid(sceneName, glossy, relief, shading::defaultSpecularGrid(*scene),
                      shading::defaultDiffuseGrid(*scene), args.frames, args.width, args.height,
                      rows) ||
            !printFit(sceneName, rows, glossy, relief)) {
            return 1;
        }
        Row middle;
        middle.lights = 32;
        middle.samples = glossy ? 16 : 0;
        middle.dirs = relief ? 8 : 0;
        if (!timeWalls(sceneName, middle, walled.string(), args.frames, args.width, args.height,
                       3)) {
            return 1;
        }
    }
    std::filesystem::remove_all(walled);
    return 0;
}
