// Speed against error of the booth renderer as the appliance runs it, for every shipped scene and
// booth light: each setting (median-cut lights 8-128 as areas and as points; on glossy scenes the
// specular sample count 1-64) is built into an appliance ('replica run' defaults otherwise,
// adaptive_k6), and the whole frame (pass 1 and the display pass, read back as loop_bench does)
// is timed as the median of many frames (wall clock, and the process's CPU time: every llvmpipe
// thread, what a shared machine's other load does not inflate), with the eye moving and the tilt
// still (pass 1 from its cache) and with the tilt moving a degree a frame (pass 1 recomputing). Its
// error is the GL booth pass with the same settings against the exact reference (36 bands, every
// luminance texel): CIEDE2000 mean / p95 / max, the worst over three tilts. One CSV row per
// setting; the plots are drawn from it by tools/render_plots.sh (docs/rendering.md, "Speed against
// error"). Usage: replica_bench_pareto [--out CSV] [--frames N] [--size WxH] [--error-size WxH]
//                             [--scene NAME] [--light NAME] [--quick]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <tests/benchmarks/frame_timing.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <platform/appliance.h>
#include <platform/output/output.h>

using namespace replica;
using namespace replica::pipeline;

namespace {

struct Options {
    std::string out = "render_pareto.csv";
    int frames = 15;
    int width = 960;
    int height = 600;
    int errorWidth = 64;
    int errorHeight = 40;
    std::string scene;
    std::string light;
    bool quick = false; // fewer settings (a smoke run)
};

struct Setting {
    std::string family; // "area lights", "point lights", "specular samples"
    std::string label;
    int lights = 32;
    int areaLights = platform::kAutoAreaLights;
    int samples = platform::kAutoSpecularSamples;
    bool isDefault = false;
};

// The appliance's frame for 'c', timed (bench::timeFrames). Returns the configuration as the
// appliance resolved it (the scene's defaults filled in).
bool timeAppliance(const platform::RunConfig& c,
                   int lampIndex,
                   int frames,
                   bench::FrameTimes& eye,
                   bench::FrameTimes& tilt,
                   platform::RunConfig& resolved)
{
    auto app = platform::buildAppliance(c);
    if (!app) {
        std::fprintf(stderr, "appliance: %s\n", app.error().message.c_str());
        return false;
    }
    resolved = (*app)->config;
    return bench::timeFrames(**app, lampIndex, frames, eye, tilt);
}

} // namespace

int main(int argc, char** argv)
{
    Options o;
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        const bool hasValue = a + 1 < argc;
        if (arg == "--help" || arg == "-h") {
            std::printf("usage: %s [--out CSV] [--frames N] [--size WxH] [--error-size WxH] "
                        "[--scene NAME] [--light NAME] [--quick]\n"
                        "Times the appliance's whole frame (median of N frames, default 15, at "
                        "WxH, default 960x600) and measures dE00 against the exact reference "
                        "(error frame default 64x40, worst of tilts 10, 30, 50) for each setting "
                        "on every shipped scene and booth light; one CSV row per setting "
                        "(default render_pareto.csv). tools/render_plots.sh draws the plots.\n",
                        argv[0]);
            return 0;
        }
        if (arg == "--quick") {
            o.quick = true;
        } else if (hasValue && arg == "--out") {
            o.out = argv[++a];
        } else if (hasValue && arg == "--frames") {
            o.frames = std::max(1, std::atoi(argv[++a]));
        } else if (hasValue && arg == "--size") {
            if (std::sscanf(argv[++a], "%dx%d", &o.width, &o.height) != 2) {
                std::fprintf(stderr, "--size: expected WIDTHxHEIGHT, got %s\n", argv[a]);
                return 2;
            }
        } else if (hasValue && arg == "--error-size") {
            if (std::sscanf(argv[++a], "%dx%d", &o.errorWidth, &o.errorHeight) != 2) {
                std::fprintf(stderr, "--error-size: expected WIDTHxHEIGHT, got %s\n", argv[a]);
                return 2;
            }
        } else if (hasValue && arg == "--scene") {
            o.scene = argv[++a];
        } else if (hasValue && arg == "--light") {
            o.light = argv[++a];
        } else {
            std::fprintf(stderr, "unknown argument %s (see --help)\n", arg.c_str());
            return 2;
        }
    }
    auto obs = colour::loadCie1931(dataDir());
    auto booth = booth::loadBooth(dataDir() / "booth");
    auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
    if (!obs || !booth || !encoder) {
        std::fprintf(stderr, "cannot set up: data missing\n");
        return 1;
    }
    std::ofstream csv(o.out);
    if (!csv) {
        std::fprintf(stderr, "%s: cannot write\n", o.out.c_str());
        return 1;
    }
    csv << "scene,light,family,setting,lights,area_lights,specular_samples,horizon_directions,"
           "is_default,frame_width,frame_height,frames,ms_eye_median,ms_eye_p10,ms_eye_p90,"
           "ms_tilt_median,ms_tilt_p10,ms_tilt_p90,de00_mean,de00_p95,de00_max,cpu_ms_eye_median,"
           "cpu_ms_eye_p10,cpu_ms_eye_p90,cpu_ms_tilt_median,cpu_ms_tilt_p10,cpu_ms_tilt_p90\n";
    const std::vector<int> lightCounts =
            o.quick ? std::vector<int>{8, 32} : std::vector<int>{8, 32, 128};
    const std::vector<int> sampleCounts =
            o.quick ? std::vector<int>{2, 8} : std::vector<int>{2, 8, 32};
    const std::vector<double> tilts{10.0, 30.0, 50.0};
    for (const char* sceneName : {"colorchecker", "metamer", "painting"}) {
        if (!o.scene.empty() && o.scene != sceneName) {
            continue;
        }
        auto scene = surface::loadScene(dataDir() / "scenes" / sceneName);
        if (!scene) {
            std::fprintf(stderr, "%s\n", scene.error().message.c_str());
            return 1;
        }
        std::vector<Setting> settings;
        settings.push_back({"default", "appliance default", 32, platform::kAutoAreaLights,
                            platform::kAutoSpecularSamples, true});
        // Each setting once: the default's own (32 lights, areas on flat scenes and points on
        // relief, the scene's sample count) is the "default" row.
        const int defaultArea = shading::defaultAreaLights(*scene) ? 1 : 0;
        const int defaultSamples = shading::defaultSpecularSamples(*scene);
        for (const int n : lightCounts) {
            for (const int area : {1, 0}) {
                if (n == 32 && area == defaultArea) {
                    continue;
                }
                settings.push_back({area ? "area lights" : "point lights",
                                    std::to_string(n) + (area ? " area lights" : " point lights"),
                                    n, area, platform::kAutoSpecularSamples, false});
            }
        }
        if (scene->glossy()) {
            for (const int n : sampleCounts) {
                if (n == defaultSamples) {
                    continue;
                }
                settings.push_back({"specular samples", std::to_string(n) + " specular samples", 32,
                                    platform::kAutoAreaLights, n, false});
            }
        }
        for (std::size_t li = 0; li < booth->lights.size(); ++li) {
            const auto& light = booth->lights[li];
            if (!o.light.empty() && o.light != light.name) {
                continue;
            }
            auto basis = encoder->basisFor(light.spd);
            if (!basis) {
                std::fprintf(stderr, "%s\n", basis.error().message.c_str());
                return 1;
            }
            std::vector<shading::View> views;
            std::vector<shading::XyzFrame> refs;
            for (const double tiltDeg : tilts) {
                shading::View v;
                v.panel = scene::panelPose(scene::degreesToRadians(tiltDeg));
                v.pixelsX = o.errorWidth;
                v.pixelsY = o.errorHeight;
                views.push_back(v);
                refs.push_back(reference::renderReference(*scene, light, v, *obs));
            }
            for (const Setting& s : settings) {
                platform::RunConfig c; // the defaults 'replica run' uses
                c.width = o.width;
                c.height = o.height;
                c.sceneDir = std::string("scenes/") + sceneName;
                c.boothLights = s.lights;
                c.areaLights = s.areaLights;
                c.specularSamples = s.samples;
                bench::FrameTimes eye, tilt;
                platform::RunConfig resolved;
                if (!timeAppliance(c, static_cast<int>(li), o.frames, eye, tilt, resolved)) {
                    return 1;
                }
                // The same settings on the GL booth pass against the reference; pass 1 keeps the
                // flare in (the reference's convention) and draws in one slice.
                shading::RenderSettings rs = platform::boothRenderSettings(resolved);
                rs.subtractFlare = true;
                rs.cacheSlices = 1;
                double mean = 0.0, p95 = 0.0, max = 0.0;
                {
                    auto output = platform::createHeadlessOutput();
                    if (!output) {
                        std::fprintf(stderr, "no GL context: %s\n", output.error().message.c_str());
                        return 1;
                    }
                    const auto ps = shading::prepareScene(*scene, std::max(rs.horizonDirections, 1),
                                                          0.01, *basis);
                    const auto pl = shading::prepareLight(light, *obs, rs.lights, *basis);
                    auto pass = render::BoothShadingPass::create(ps, rs, *obs);
                    if (!pass || !(*pass)->setLight(pl)) {
                        std::fprintf(stderr, "GL pass failed\n");
                        return 1;
                    }
                    for (std::size_t v = 0; v < views.size(); ++v) {
                        auto f = render::renderBoothFrame(**pass, pl, views[v]);
                        if (!f) {
                            std::fprintf(stderr, "%s\n", f.error().message.c_str());
                            return 1;
                        }
                        const auto e = reference::compareFrames(refs[v], *f);
                        mean = std::max(mean, e.mean);
                        p95 = std::max(p95, e.p95);
                        max = std::max(max, e.max);
                    }
                }
                const int horizon = scene->flat() ? 0 : resolved.horizonDirections;
                const int samples = scene->glossy() ? resolved.specularSamples : 0;
                char line[512];
                std::snprintf(line, sizeof line,
                              "%s,%s,%s,%s,%d,%d,%d,%d,%d,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,"
                              "%.4f,%.4f,%.4f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f\n",
                              sceneName, light.name.c_str(), s.family.c_str(), s.label.c_str(),
                              resolved.boothLights, resolved.areaLights, samples, horizon,
                              s.isDefault ? 1 : 0, o.width, o.height, o.frames, eye.wall.median,
                              eye.wall.p10, eye.wall.p90, tilt.wall.median, tilt.wall.p10,
                              tilt.wall.p90, mean, p95, max, eye.cpu.median, eye.cpu.p10,
                              eye.cpu.p90, tilt.cpu.median, tilt.cpu.p10, tilt.cpu.p90);
                csv << line;
                csv.flush();
                std::fputs(line, stdout);
                std::fflush(stdout);
            }
        }
    }
    return 0;
}
