// The planner in the loop: for a scene and every booth lamp, the cheapest lights / specular samples
// / horizon directions (and, under a booth with walls, whether to draw them) that meet the ΔE00
// budget from the planner's probe views
// (shading::planRenderViews), computed once and cached in a file keyed by the scene, booth and
// basis, and recorded in a run's configuration (RunConfig::plannedLamps) so replay draws the same.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/tuning/planner.h>

namespace replica::platform {

// One lamp's choice. Everything else in the renderer's settings stays as the run configures it.
struct LampPlan {
    int lights = 32;
    int specularSamples = 0;
    int horizonDirections = 8;
    double probeP95 = 0.0; // worst over the probe views, against the exact reference
    double probeMax = 0.0;
    bool met = false; // false: nothing met the budget; the most accurate setting tried
    // Light the surface from the booth's walls (a booth that declares them; no effect otherwise).
    // True where a plan or a recording does not say: every lamp of a booth with walls drew them
    // before the planner chose.
    bool walls = true;
    bool operator==(const LampPlan& o) const
    {
        return lights == o.lights && specularSamples == o.specularSamples &&
               horizonDirections == o.horizonDirections && walls == o.walls;
    }
};

struct RenderPlan {
    std::string sceneDigest;
    std::string boothDigest;
    std::string basis;
    std::map<std::string, LampPlan> lamps;
};

// The plan file's text ("replica-plan/1") and its reader. The reader refuses anything malformed
// with one line naming the file and what is wrong (counts out of the renderer's range included).
std::string renderPlanJson(const RenderPlan& plan);
Expected<RenderPlan> parseRenderPlan(const std::string& text, const std::string& source);
Expected<RenderPlan> readRenderPlan(const std::filesystem::path& path);
Expected<void> writeRenderPlan(const std::filesystem::path& path, const RenderPlan& plan);

// FNV-1a 64 (hex) of booth.json and the images it names in 'boothDir'.
Expected<std::string> boothDigest(const std::filesystem::path& boothDir);

// Where the plan for these digests lives under 'cacheDir'.
std::filesystem::path renderPlanPath(const std::filesystem::path& cacheDir,
                                     const std::string& sceneName,
                                     const std::string& sceneDigest,
                                     const std::string& boothDigest,
                                     const std::string& basis);

// The default cache folder: $REPLICA_PLAN_CACHE, else $XDG_CACHE_HOME/replica/plans, else
// $HOME/.cache/replica/plans, else /var/tmp/replica-plans.
std::filesystem::path defaultPlanCacheDir();

// The planner's probe (pipeline/tuning/planner.h, probeViews) and budget for the appliance's
// plans: the tilts 10, 30 and 50 degrees from kPlanProbeEyes eyes at kPlanProbeWidth x
// kPlanProbeHeight pixels against the exact reference. The budget is ΔE00 p95 <= 1 and max <= 3
// (kPlanBudget); the probe must meet it with the margin kPlanMargin (p95 <= 0.75, max <= 2.25),
// because a coarse probe flatters: the ColorChecker's d65 pick at p95 0.962 on the 32x20 probe
// is 1.192 on the 64x40 nine-view check ('replica plan --check 64x40'), 1.24 times as much.
constexpr int kPlanProbeWidth = 32;
constexpr int kPlanProbeHeight = 20;
constexpr int kPlanProbeEyes = 3;
inline constexpr pipeline::shading::ErrorBudget kPlanBudget{1.0, 3.0};
constexpr double kPlanMargin = 0.75;

// Each planned lamp's setting measured again on another probe (probeViews at probeX x probeY,
// 'eyes' eyes) against the exact reference: the worst mean, p95 and max over its views, per lamp
// name. 'replica plan --check' prints it; the plan's picks must hold on a finer probe too.
Expected<std::map<std::string, pipeline::reference::FrameError>>
checkRenderPlan(const std::filesystem::path& sceneDir,
                const std::filesystem::path& boothDir,
                const RenderPlan& plan,
                int probeX,
                int probeY,
                int eyes);

// Computes the plan for the scene folder and every light of the booth folder, with the
// appliance's settings for the rest ('areaLights' as the appliance will draw). Minutes on a slow
// CPU.
Expected<RenderPlan> computeRenderPlan(const std::filesystem::path& sceneDir,
                                       const std::filesystem::path& boothDir,
                                       const std::string& basis);

// The plan for the scene: the cached one in 'cacheDir', else the one shipped with the scene (the
// same file name in 'sceneDir': 'replica plan --scene S --plan-cache S --force' writes it), else,
// with 'compute', computed once and written to the cache (a log line says so). Without 'compute'
// and no plan: an error of code NotFound that says how to plan.
Expected<RenderPlan> loadOrComputeRenderPlan(const std::filesystem::path& sceneDir,
                                             const std::filesystem::path& boothDir,
                                             const std::string& basis,
                                             const std::filesystem::path& cacheDir,
                                             bool compute = true);

} // namespace replica::platform
