// Calibrates the planner's cost model (pipeline/tuning/planner.cpp, settingCost) to the GL frame:
// for every shipped scene a grid of the settings the planner chooses between (median-cut lights;
// specular samples on glossy scenes; horizon directions on scenes with relief) is built into an
// appliance ('replica run' defaults otherwise, adaptive_k6, 960x600) and its whole frame (both
// passes, display read-back) timed as the median of N frames with the tilt moving a degree a frame
// (pass 1 recomputing its diffuse term in bands: the frame the loop's deadline must hold while the
// panel moves) and with the eye moving (pass 1 from its cache). Then, per scene class, the least
// squares fit of the tilt-moving CPU-time median (every llvmpipe thread; steadier than the wall
// clock on a shared machine) to t0 + L * lights + H * horizon directions + S * specular samples,
// printed with each setting's measured and predicted time. The coefficients go into
// settingCost (docs/rendering.md, "Planner"); run this again to refit after a renderer change.
// Usage: replica_bench_cost_model [--frames N] [--size WxH] [--scene NAME]
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <tests/benchmarks/frame_bench_args.h>
#include <tests/benchmarks/frame_timing.h>

#include <pipeline/base/data_dir.h>
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

bool timeSetting(const std::string& scene, Row& r, int frames, int w, int h)
{
    platform::RunConfig c;
    c.width = w;
    c.height = h;
    c.sceneDir = "scenes/" + scene;
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

} // namespace

int main(int argc, char** argv)
{
    replica::bench::FrameBenchArgs args;
    args.frames = 9;
    if (auto stop = replica::bench::parseFrameBenchArgs(
                argc, argv, args, 3,
                "Times the appliance's frame over a grid of planner settings on every shipped "
                "scene and fits the planner's cost model to it.")) {
        return *stop;
    }
    const int frames = args.frames;
    const int w = args.width;
    const int h = args.height;
    const std::string only = args.scene;
    std::printf("%dx%d, median of %d frames; ms\n", w, h, frames);
    for (const char* sceneName : {"metamer", "colorchecker", "painting"}) {
        if (!only.empty() && only != sceneName) {
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
                    r.modelCost = shading::settingCost(rs, glossy, relief);
                    if (!timeSetting(sceneName, r, frames, w, h)) {
                        return 1;
                    }
                    std::printf("%s lights %d samples %d dirs %d: tilt cpu %.1f wall %.1f, eye cpu "
                                "%.1f wall %.1f, cost model %.1f\n",
                                sceneName, l, s, d, r.tiltCpu, r.tiltWall, r.eyeCpu, r.eyeWall,
                                r.modelCost);
                    std::fflush(stdout);
                    rows.push_back(r);
                }
            }
        }
        // t0 + L lights + H dirs + S samples, the columns the scene varies.
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
            std::fprintf(stderr, "%s: the fit is singular\n", sceneName);
            return 1;
        }
        const double perLight = beta[1];
        const double perDir = relief ? beta[2] : 0.0;
        const double perSample = glossy ? beta[relief ? 3 : 2] : 0.0;
        std::printf(
                "\n%s fit (tilt-moving CPU ms): t0 %.2f + %.4f/light + %.4f/horizon direction + "
                "%.4f/specular sample; in light units: direction %.3f, sample %.3f\n",
                sceneName, beta[0], perLight, perDir, perSample,
                perLight > 0 ? perDir / perLight : 0.0, perLight > 0 ? perSample / perLight : 0.0);
        std::printf("| lights | samples | dirs | measured ms | fitted ms | settingCost |\n"
                    "|---|---|---|---|---|---|\n");
        for (std::size_t i = 0; i < rows.size(); ++i) {
            double fit = 0.0;
            for (std::size_t k = 0; k < beta.size(); ++k) {
                fit += beta[k] * x[i][k];
            }
            std::printf("| %d | %d | %d | %.1f | %.1f | %.1f |\n", rows[i].lights, rows[i].samples,
                        rows[i].dirs, rows[i].tiltCpu, fit, rows[i].modelCost);
        }
        std::printf("\n");
    }
    return 0;
}
