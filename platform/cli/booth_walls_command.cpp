// 'replica booth walls': how much light from the booth's walls changes what the display shows
// (ΔE00 of the exact reference with walls against without, for each lamp and scene), and how
// well the real-time renderer's approximation of it (shading/wall_field.h) holds the budget.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/booth/booth_walls.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/reference/wall_radiosity.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/scene/booth.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/wall_field.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/surface/surface_scene.h>
#include <platform/cli/commands.h>

namespace replica::platform {
namespace {

using namespace pipeline;

struct WallsArgs {
    std::string booth;
    std::vector<std::string> scenes{"colorchecker", "painting"};
    std::vector<double> tilts{30.0};
    int width = 64;
    int height = 40;
    double reflectance = booth::kMunsellN7Reflectance;
    double patchM = 0.05;                                // the reference's patches
    double realtimePatchM = render::kRealtimeWallPatchM; // the real-time renderer's
};

double msSince(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string pair(const reference::FrameError& e)
{
    return fmt::format("{:5.2f} / {:5.2f}", e.p95, e.max);
}

// One row of the table: one lamp, scene and tilt.
struct Row {
    reference::FrameError walls, realtimeWithout, realtimeWith, realtimeBase;
    double fieldUs = 0.0;
};

Row studyView(const surface::SurfaceScene& scene,
              const booth::BoothLight& light,
              const booth::WallLight& fine,
              const booth::WallLight& coarse,
              const shading::View& view,
              const colour::Observer& obs,
              const colour::ChannelBasis& basis)
{
    Row r;
    reference::ReferenceOptions without;
    reference::ReferenceOptions with;
    with.walls = &fine;
    const auto ref0 = reference::renderReference(scene, light, view, obs, without);
    const auto ref1 = reference::renderReference(scene, light, view, obs, with);
    r.walls = reference::compareFrames(ref1, ref0);
    shading::RenderSettings s;
    s.specularSamples = shading::defaultSpecularSamples(scene);
    s.specularGrid = shading::defaultSpecularGrid(scene);
    s.diffuseGrid = shading::defaultDiffuseGrid(scene);
    s.areaLights = shading::defaultAreaLights(scene);
    auto pl = shading::prepareLight(light, obs, s.lights, basis);
    pl.walls = &coarse;
    const auto ps = shading::prepareScene(scene, s.horizonDirections, 0.01, basis);
    const auto rt0 = shading::renderRealtime(ps, pl, view, obs, s);
    s.walls = true;
    const auto rt1 = shading::renderRealtime(ps, pl, view, obs, s);
    r.realtimeWithout = reference::compareFrames(ref1, rt0);
    r.realtimeWith = reference::compareFrames(ref1, rt1);
    r.realtimeBase = reference::compareFrames(ref0, rt0);
    const int n = 200;
    const auto t0 = std::chrono::steady_clock::now();
    volatile double sink = 0.0;
    for (int k = 0; k < n; ++k) {
        sink = sink + shading::wallField(coarse, view.panel, scene).nodes[4];
    }
    r.fieldUs = msSince(t0) * 1000.0 / n;
    return r;
}

int runWalls(const WallsArgs& a)
{
    auto booth = booth::loadBooth(a.booth.empty() ? dataDir() / "booth"
                                                  : std::filesystem::path(a.booth));
    auto obs = colour::loadCie1931(dataDir());
    auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
    if (!booth || !obs || !encoder) {
        std::fprintf(stderr, "replica booth walls: %s\n",
                     (!booth ? booth.error()
                      : !obs ? obs.error()
                             : encoder.error())
                             .message.c_str());
        return kExitFailure;
    }
    std::vector<surface::SurfaceScene> scenes;
    for (const auto& name : a.scenes) {
        auto s = surface::loadScene(name.find('/') == std::string::npos
                                            ? dataDir() / "scenes" / name
                                            : std::filesystem::path(name));
        if (!s) {
            std::fprintf(stderr, "replica booth walls: %s\n", s.error().message.c_str());
            return kExitFailure;
        }
        scenes.push_back(std::move(*s));
    }
    std::printf("Walls: %.4f reflectance (flat), the box under the ceiling down to the floor, "
                "front open; reference patches %.3f m, real-time %.3f m; %dx%d frames, "
                "default eye.\nΔE00 p95 / max against the exact reference with walls.\n",
                a.reflectance, a.patchM, a.realtimePatchM, a.width, a.height);
    std::printf("%-16s %-13s %4s | %-13s | %-7s | %-13s | %-13s | %-15s | %8s | %8s\n", "lamp",
                "scene", "tilt", "walls vs none", "matters", "rt no walls", "rt walls",
                "(before: rt vs", "field us", "solve ms");
    std::printf("%-16s %-13s %4s | %-13s | %-7s | %-13s | %-13s | %-15s | %8s | %8s\n", "", "", "",
                "", "", "", "", " ref no walls)", "per pose", "rt walls");
    for (const auto& light : booth->lights) {
        booth::BoothWalls walls = scene::defaultBoothWalls(booth->ceiling());
        walls.reflectance = colour::Spectrum::constant(a.reflectance);
        auto t0 = std::chrono::steady_clock::now();
        reference::WallSolveOptions fineOpt;
        fineOpt.patchM = a.patchM;
        const auto fine = reference::solveWalls(walls, light, *obs, fineOpt);
        const double solveMs = msSince(t0);
        reference::WallSolveOptions coarseOpt;
        coarseOpt.patchM = a.realtimePatchM;
        t0 = std::chrono::steady_clock::now();
        const auto coarse = reference::solveWalls(walls, light, *obs, coarseOpt);
        const double coarseMs = msSince(t0);
        auto basis = encoder->basisFor(light.spd);
        if (!basis) {
            std::fprintf(stderr, "replica booth walls: %s\n", basis.error().message.c_str());
            return kExitFailure;
        }
        for (const auto& scene : scenes) {
            for (const double tilt : a.tilts) {
                shading::View view;
                view.pixelsX = a.width;
                view.pixelsY = a.height;
                view.panel = scene::panelPose(scene::degreesToRadians(tilt));
                const Row r = studyView(scene, light, fine, coarse, view, *obs, *basis);
                // Over the budget (p95 1, max 3) without them: the walls matter.
                const bool matters = r.walls.p95 > 1.0 || r.walls.max > 3.0;
                std::printf("%-16s %-13s %4.0f | %s | %-7s | %s | %s |  %s  | %8.1f | %8.0f\n",
                            light.name.c_str(), scene.name.c_str(), tilt, pair(r.walls).c_str(),
                            matters ? "yes" : "no", pair(r.realtimeWithout).c_str(),
                            pair(r.realtimeWith).c_str(), pair(r.realtimeBase).c_str(), r.fieldUs,
                            coarseMs);
                std::fflush(stdout);
            }
        }
        std::printf("  %s: reference solve %.0f ms, %zu patches, %d iterations, residual %.1e\n",
                    light.name.c_str(), solveMs, fine.patches.size(), fine.iterations,
                    fine.residual);
    }
    return kExitOk;
}

} // namespace

void registerBoothWallsCommand(CLI::App& booth, int& exitCode)
{
    auto args = std::make_shared<WallsArgs>();
    CLI::App* cmd = booth.add_subcommand(
            "walls", "how much light from the booth's walls changes the ColorChecker and the "
                     "painting under each lamp (ΔE00 with against without), and the real-time "
                     "approximation's error (docs/rendering.md, \"The booth's walls\")");
    cmd->add_option("--booth", args->booth, "booth folder (default: the shipped data/booth)");
    cmd->add_option("--scene", args->scenes,
                    "shipped scene names or scene folders (default: colorchecker painting)");
    cmd->add_option("--tilt", args->tilts, "panel tilts in degrees (default: 30)");
    cmd->add_option("--width", args->width, "frame width in pixels (default 64)")
            ->check(CLI::Range(1, 1024));
    cmd->add_option("--height", args->height, "frame height in pixels (default 40)")
            ->check(CLI::Range(1, 1024));
    cmd->add_option("--reflectance", args->reflectance,
                    "the walls' (flat) reflectance (default Munsell N7, 0.4306)")
            ->check(CLI::Range(0.0, 0.99));
    cmd->add_option("--patch", args->patchM, "the reference's wall patches, metres (0.05)")
            ->check(CLI::Range(0.005, 1.0));
    cmd->add_option(
               "--realtime-patch", args->realtimePatchM,
               "the real-time renderer's wall patches, metres (default: the appliance's, 0.35)")
            ->check(CLI::Range(0.005, 1.0));
    cmd->callback([args, &exitCode] { exitCode = runWalls(*args); });
}

} // namespace replica::platform
