// Speed-vs-error sweep of the booth/surface renderer (CPU model of the real-time algorithm) against
// the exact reference, on every shipped scene and light; prints markdown tables, writes a Pareto
// PNG. Usage: replica_bench_render [OUT_DIR] [WIDTHxHEIGHT of the error frame, default 96x60]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <png.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/shading/planner.h>
#include <pipeline/shading/realtime_model.h>

using namespace replica;
using namespace replica::pipeline;

namespace {

struct Point {
    std::string label;
    double msFullHd = 0.0; // projected to 1920x1200
    double p95 = 0.0;
    double mean = 0.0;
    double max = 0.0;
};

double timeFrame(const shading::PreparedScene& ps,
                 const shading::PreparedLight& pl,
                 const shading::View& v,
                 const colour::Observer& obs,
                 const shading::RenderSettings& s,
                 shading::XyzFrame& out)
{
    const auto t0 = std::chrono::steady_clock::now();
    out = shading::renderRealtime(ps, pl, v, obs, s);
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void writePareto(const std::filesystem::path& file, const std::vector<Point>& pts)
{
    const int w = 720, h = 480, m = 50;
    std::vector<png_byte> img(static_cast<std::size_t>(w * h * 3), 255);
    const auto put = [&](int x, int y, int r, int g, int b) {
        if (x < 0 || y < 0 || x >= w || y >= h) {
            return;
        }
        const std::size_t k = static_cast<std::size_t>((y * w + x) * 3);
        img[k] = static_cast<png_byte>(r);
        img[k + 1] = static_cast<png_byte>(g);
        img[k + 2] = static_cast<png_byte>(b);
    };
    double x0 = 1e30, x1 = 0, y1 = 0;
    for (const auto& p : pts) {
        x0 = std::min(x0, p.msFullHd);
        x1 = std::max(x1, p.msFullHd);
        y1 = std::max(y1, p.p95);
    }
    const double lx0 = std::log10(x0) - 0.05, lx1 = std::log10(x1) + 0.05;
    y1 = std::max(y1 * 1.05, 1.0);
    const auto sx = [&](double ms) {
        return m + static_cast<int>((std::log10(ms) - lx0) / (lx1 - lx0) * (w - 2 * m));
    };
    const auto sy = [&](double de) { return h - m - static_cast<int>(de / y1 * (h - 2 * m)); };
    for (int x = m; x < w - m; ++x) {
        put(x, h - m, 0, 0, 0);
        put(x, sy(1.0), 180, 180, 180); // the dE00 p95 = 1 budget line
    }
    for (int y = m; y < h - m; ++y) {
        put(m, y, 0, 0, 0);
    }
    for (double dec = std::ceil(lx0); dec <= lx1; dec += 1.0) { // decade ticks
        for (int y = h - m; y < h - m + 8; ++y) {
            put(sx(std::pow(10.0, dec)), y, 0, 0, 0);
        }
    }
    std::vector<Point> sorted = pts;
    std::sort(sorted.begin(), sorted.end(),
              [](const Point& a, const Point& b) { return a.msFullHd < b.msFullHd; });
    double best = 1e30;
    for (const auto& p : sorted) {
        const bool front = p.p95 < best;
        best = std::min(best, p.p95);
        for (int dy = -3; dy <= 3; ++dy) {
            for (int dx = -3; dx <= 3; ++dx) {
                put(sx(p.msFullHd) + dx, sy(p.p95) + dy, front ? 220 : 60, front ? 30 : 90,
                    front ? 30 : 200);
            }
        }
    }
    png_image pi{};
    pi.version = PNG_IMAGE_VERSION;
    pi.width = static_cast<png_uint_32>(w);
    pi.height = static_cast<png_uint_32>(h);
    pi.format = PNG_FORMAT_RGB;
    png_image_write_to_file(&pi, file.c_str(), 0, img.data(), 0, nullptr);
}

} // namespace

int main(int argc, char** argv)
{
    const std::filesystem::path outDir = argc > 1 ? argv[1] : "render_sweep";
    int fw = 96, fh = 60;
    if (argc > 2) {
        std::sscanf(argv[2], "%dx%d", &fw, &fh);
    }
    std::filesystem::create_directories(outDir);
    auto obs = colour::loadCie1931(dataDir());
    auto booth = booth::loadBooth(dataDir() / "booth");
    if (!obs || !booth) {
        std::fprintf(stderr, "cannot load data: %s\n",
                     (!obs ? obs.error() : booth.error()).message.c_str());
        return 1;
    }
    const double scale = (1920.0 * 1200.0) / (static_cast<double>(fw) * fh);
    const double tilt = 30.0;
    std::printf("# booth/surface renderer sweep (CPU model, 2 threads), error frame %dx%d, tilt "
                "%.0f deg, eye (0, 0.45, 0.60)\n\n",
                fw, fh, tilt);
    std::printf(
            "ms columns: CPU-model time for the error frame projected to 1920x1200 (x%.0f).\n\n",
            scale);
    std::printf("| scene | light | setting | ms 1920x1200 | dE00 mean | p95 | max "
                "|\n|---|---|---|---|---|---|---|\n");
    std::vector<Point> pareto;
    std::vector<std::string> planLines;
    for (const char* sceneName : {"colorchecker", "metamer", "painting"}) {
        auto scene = surface::loadScene(dataDir() / "scenes" / sceneName);
        if (!scene) {
            std::fprintf(stderr, "%s\n", scene.error().message.c_str());
            return 1;
        }
        for (const auto& light : booth->lights) {
            shading::View view;
            view.panel = shading::panelPoseFromTilt(tilt);
            view.pixelsX = fw;
            view.pixelsY = fh;
            const auto ref = reference::renderReference(*scene, light, view, *obs);
            std::vector<std::pair<std::string, shading::RenderSettings>> configs;
            const shading::RenderSettings def;
            configs.emplace_back("default (32 lights, 16 spec, 8 horizon, box6)", def);
            for (int n : {8, 16, 64, 128, 256}) {
                auto s = def;
                s.lights = n;
                configs.emplace_back(std::to_string(n) + " lights", s);
            }
            if (scene->glossy()) {
                for (int n : {1, 4, 8, 32, 64}) {
                    auto s = def;
                    s.specularSamples = n;
                    configs.emplace_back(std::to_string(n) + " spec samples", s);
                }
            }
            if (!scene->flat()) {
                auto s = def;
                s.horizonDirections = 16;
                configs.emplace_back("16 horizon dirs", s);
                s.reliefPass = false;
                configs.emplace_back("no relief pass", s);
            }
            {
                auto s = def;
                s.channels = shading::ChannelRep::Spectral36;
                configs.emplace_back("spectral36 channels", s);
            }
            double defaultMs = 0.0;
            for (const auto& [label, s] : configs) {
                const auto pl = shading::prepareLight(light, *obs, s.lights);
                const auto ps = shading::prepareScene(*scene, std::max(s.horizonDirections, 1));
                shading::XyzFrame f;
                const double ms = timeFrame(ps, pl, view, *obs, s, f) * scale;
                const auto e = reference::compareFrames(ref, f);
                if (label.rfind("default", 0) == 0) {
                    defaultMs = ms;
                }
                std::printf("| %s | %s | %s | %.0f | %.3f | %.3f | %.3f |\n", sceneName,
                            light.name.c_str(), label.c_str(), ms, e.mean, e.p95, e.max);
                std::fflush(stdout);
            }
            // Planner: cheapest setting meeting p95 <= 1, max <= 3 on a 32x20 probe; then timed at
            // full size.
            const auto plan = shading::planRender(*scene, light, view, *obs);
            const auto pl = shading::prepareLight(light, *obs, plan.settings.lights);
            const auto ps =
                    shading::prepareScene(*scene, std::max(plan.settings.horizonDirections, 1));
            shading::XyzFrame f;
            const double ms = timeFrame(ps, pl, view, *obs, plan.settings, f) * scale;
            const auto e = reference::compareFrames(ref, f);
            std::string skipped;
            for (const auto& sk : plan.skipped) {
                skipped += (skipped.empty() ? "" : "; ") + sk.substr(0, sk.find(':'));
            }
            char line[512];
            std::snprintf(line, sizeof line,
                          "| %s | %s | %d lights, %d spec, %d horizon | %s | %d | %.0f | %.0f | "
                          "%.2f | %.3f | %.3f |",
                          sceneName, light.name.c_str(), plan.settings.lights,
                          scene->glossy() ? plan.settings.specularSamples : 0,
                          scene->flat() ? 0 : plan.settings.horizonDirections,
                          skipped.empty() ? "-" : skipped.c_str(), plan.evaluated, ms, defaultMs,
                          defaultMs / std::max(ms, 1e-9), e.p95, e.max);
            planLines.emplace_back(line);
            if (std::string(sceneName) == "painting" && light.name == "d65-fluorescent") {
                for (int n : {8, 16, 32, 64, 128, 256}) {
                    for (int spp : {1, 4, 8, 16, 32, 64}) {
                        for (int dirs : {8, 16}) {
                            shading::RenderSettings s;
                            s.lights = n;
                            s.specularSamples = spp;
                            s.horizonDirections = dirs;
                            const auto pl2 = shading::prepareLight(light, *obs, n);
                            const auto ps2 = shading::prepareScene(*scene, dirs);
                            shading::XyzFrame f2;
                            const double ms2 = timeFrame(ps2, pl2, view, *obs, s, f2) * scale;
                            const auto e2 = reference::compareFrames(ref, f2);
                            pareto.push_back({std::to_string(n) + "/" + std::to_string(spp) + "/" +
                                                      std::to_string(dirs),
                                              ms2, e2.p95, e2.mean, e2.max});
                        }
                    }
                }
            }
        }
    }
    std::printf("\n## planner (budget dE00 p95 <= 1, max <= 3)\n\n| scene | light | chosen | "
                "skipped | candidates tried | ms "
                "1920x1200 | default ms | saving x | p95 | max "
                "|\n|---|---|---|---|---|---|---|---|---|---|\n");
    for (const auto& l : planLines) {
        std::printf("%s\n", l.c_str());
    }
    std::printf("\n## Pareto front, painting under d65-fluorescent (lights/spec samples/horizon "
                "dirs)\n\n| setting | ms "
                "1920x1200 | p95 | mean | max |\n|---|---|---|---|---|\n");
    std::sort(pareto.begin(), pareto.end(),
              [](const Point& a, const Point& b) { return a.msFullHd < b.msFullHd; });
    double best = 1e30;
    for (const auto& p : pareto) {
        if (p.p95 < best) {
            best = p.p95;
            std::printf("| %s | %.0f | %.3f | %.3f | %.3f |\n", p.label.c_str(), p.msFullHd, p.p95,
                        p.mean, p.max);
        }
    }
    writePareto(outDir / "render_pareto.png", pareto);
    std::printf("\nPareto plot: %s (x: log ms per 1920x1200 frame, y: dE00 p95; grey line: p95 = "
                "1; red: front)\n",
                (outDir / "render_pareto.png").string().c_str());
    return 0;
}
