// replica plan: the planner's per-lamp choice for a scene, computed (or read from the cache) and
// written where 'replica run --planner' looks for it.
#include <cstdio>
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/output/display_geometry.h>
#include <platform/render_plan.h>

namespace replica::platform {

namespace {

struct PlanArgs {
    std::string scene;
    std::string booth; // empty: the shipped data/booth
    std::string basis = "adaptive_k6";
    std::string cache;
    bool force = false;
    std::string check; // WxH: the picks measured again on a probe of that size
    int eyes = 3;
};

int runPlan(const PlanArgs& a)
{
    // As 'replica run --scene': a folder that exists from here, else one under the data folder.
    std::error_code ec;
    const std::filesystem::path scene = std::filesystem::is_directory(a.scene, ec)
                                                ? std::filesystem::absolute(a.scene, ec)
                                                : resolveSceneDir(a.scene);
    const std::filesystem::path booth = a.booth.empty() ? dataDir() / "booth"
                                        : std::filesystem::is_directory(a.booth, ec)
                                                ? std::filesystem::absolute(a.booth, ec)
                                                : resolveSceneDir(a.booth);
    if (!std::filesystem::is_regular_file(booth / "booth.json", ec)) {
        std::fprintf(stderr,
                     "replica plan: --booth %s: no booth.json there; name a booth folder such as "
                     "'replica booth build' makes\n",
                     booth.string().c_str());
        return kExitUsage;
    }
    const auto boothModel = pipeline::booth::loadBooth(booth);
    const bool boothWalls = boothModel && boothModel->walls.has_value();
    const std::filesystem::path cache =
            a.cache.empty() ? defaultPlanCacheDir() : std::filesystem::path(a.cache);
    auto sd = sceneDigest(scene);
    auto bd = boothDigest(booth);
    if (!sd || !bd) {
        std::fprintf(stderr, "replica plan: %s\n", (!sd ? sd.error() : bd.error()).message.c_str());
        return kExitFailure;
    }
    const auto path = renderPlanPath(cache, scene.filename().string(), *sd, *bd, a.basis);
    if (a.force) {
        std::filesystem::remove(path, ec);
    }
    auto plan = loadOrComputeRenderPlan(scene, booth, a.basis, cache);
    if (!plan) {
        std::fprintf(stderr, "replica plan: %s\n", plan.error().message.c_str());
        return kExitFailure;
    }
    std::printf("%s\n", path.string().c_str());
    for (const auto& [name, p] : plan->lamps) {
        std::printf("%s: %d lights, %d specular samples, %d horizon directions%s; worst dE00 p95 "
                    "%.3f, max %.3f over the probe views%s\n",
                    name.c_str(), p.lights, p.specularSamples, p.horizonDirections,
                    !boothWalls ? "" : (p.walls ? ", the walls' light" : ", no walls"), p.probeP95,
                    p.probeMax, p.met ? "" : " (the budget is not met)");
    }
    if (!a.check.empty()) {
        const auto size = parsePixelSize(a.check); // the one WxH parser, checked before narrowing
        if (!size || size->first < 2 || size->second < 2 || size->first > 1024 ||
            size->second > 1024) {
            std::fprintf(stderr, "replica plan: --check %s: expected WIDTHxHEIGHT, 2-1024 each\n",
                         a.check.c_str());
            return kExitUsage;
        }
        const int w = static_cast<int>(size->first);
        const int h = static_cast<int>(size->second);
        auto checked = checkRenderPlan(scene, booth, *plan, w, h, a.eyes);
        if (!checked) {
            std::fprintf(stderr, "replica plan: %s\n", checked.error().message.c_str());
            return kExitFailure;
        }
        bool within = true;
        for (const auto& [name, e] : *checked) {
            const bool ok = e.p95 <= kPlanBudget.p95 && e.max <= kPlanBudget.max;
            within = within && ok;
            std::printf("check %dx%d, %d views: %s: worst dE00 mean %.3f, p95 %.3f, max %.3f%s\n",
                        w, h, 3 * a.eyes, name.c_str(), e.mean, e.p95, e.max,
                        ok ? "" : " (OVER the budget)");
        }
        if (!within) {
            return kExitFailure;
        }
    }
    return kExitOk;
}

} // namespace

void registerPlanCommand(CLI::App& app, int& exitCode)
{
    auto args = std::make_shared<PlanArgs>();
    CLI::App* cmd = app.add_subcommand(
            "plan", "the planner's lights, specular samples and horizon directions (and the "
                    "booth's walls, where it has them) for each lamp of the booth on a scene, "
                    "written to the cache 'replica run --planner' reads");
    cmd->add_option("--scene", args->scene,
                    "scene folder (one that does not exist from here: under the data folder)")
            ->required();
    cmd->add_option("--booth", args->booth,
                    "booth model folder to plan under (as 'replica run --booth'; default: the "
                    "shipped data/booth); a booth whose booth.json declares walls is planned with "
                    "them, each lamp drawing them where leaving them out would cost the budget");
    cmd->add_option("--basis", args->basis, "channel basis the appliance will run with")
            ->capture_default_str();
    cmd->add_option("--plan-cache", args->cache,
                    "folder of the cached plans (default as 'replica run --plan-cache')");
    cmd->add_flag("--force", args->force, "plan again even when a cached plan exists");
    cmd->add_option(
            "--check", args->check,
            "measure each lamp's pick again against the exact reference on a probe of "
            "WIDTHxHEIGHT pixels (tilts 10, 30, 50 degrees from --eyes eyes); exit 1 when a "
            "pick is over the budget there");
    cmd->add_option("--eyes", args->eyes, "eyes of the --check probe: 1-3")
            ->check(CLI::Range(1, 3))
            ->capture_default_str();
    cmd->callback([args, &exitCode] { exitCode = runPlan(*args); });
}

} // namespace replica::platform
