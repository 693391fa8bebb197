// The planner's per-lamp choice: computed, cached in a file, read back with every field checked.
#include <algorithm>
#include <cstdlib>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file.h>
#include <pipeline/base/json_limits.h>
#include <pipeline/base/output_file.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/reference/wall_radiosity.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/stand.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/tuning/planner.h>
#include <platform/appliance.h>
#include <platform/logging.h>
#include <platform/loop/frame_digest.h>
#include <platform/render_plan.h>

namespace replica::platform {

namespace {

constexpr const char* kPlanFormat = "replica-plan/1";

} // namespace

std::string renderPlanJson(const RenderPlan& plan)
{
    nlohmann::json lamps = nlohmann::json::object();
    for (const auto& [name, p] : plan.lamps) {
        lamps[name] = {{"lights", p.lights},
                       {"specular_samples", p.specularSamples},
                       {"horizon_directions", p.horizonDirections},
                       {"walls", p.walls},
                       {"probe_de00_p95", p.probeP95},
                       {"probe_de00_max", p.probeMax},
                       {"met_budget", p.met}};
    }
    const nlohmann::json j{{"format", kPlanFormat},
                           {"scene_digest", plan.sceneDigest},
                           {"booth_digest", plan.boothDigest},
                           {"basis", plan.basis},
                           {"lamps", lamps}};
    return j.dump(2) + "\n";
}

Expected<RenderPlan> parseRenderPlan(const std::string& text, const std::string& source)
{
    const auto bad = [&](const std::string& what) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: {}; delete the file and run with --planner again to plan anew",
                            source, what));
    };
    if (auto ok = checkJsonLimits(text, source); !ok) {
        return makeError(ok.error().code,
                         fmt::format("{}; delete the file and run with --planner again to plan "
                                     "anew",
                                     ok.error().message));
    }
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const std::exception& e) {
        return bad(fmt::format("not JSON ({})", e.what()));
    }
    if (!j.is_object() || !j.contains("format") || !j["format"].is_string() ||
        j["format"].get<std::string>() != kPlanFormat) {
        return bad(fmt::format("not a plan (\"format\" must be \"{}\")", kPlanFormat));
    }
    RenderPlan plan;
    for (const char* key : {"scene_digest", "booth_digest", "basis"}) {
        if (!j.contains(key) || !j[key].is_string()) {
            return bad(fmt::format("\"{}\" must be a string", key));
        }
    }
    plan.sceneDigest = j["scene_digest"].get<std::string>();
    plan.boothDigest = j["booth_digest"].get<std::string>();
    plan.basis = j["basis"].get<std::string>();
    if (!j.contains("lamps") || !j["lamps"].is_object() || j["lamps"].empty()) {
        return bad("\"lamps\" must be an object with one entry per lamp");
    }
    for (const auto& item : j["lamps"].items()) {
        // Named, not a structured binding: the lambda below captures it, which clang's C++20
        // (the libFuzzer build) refuses for a binding.
        const std::string name = item.key();
        const nlohmann::json& l = item.value();
        const auto count = [&](const char* key, int lo, int hi, int& out) -> bool {
            if (!l.is_object() || !l.contains(key) || !l[key].is_number_integer()) {
                return false;
            }
            const auto v = l[key].get<long long>();
            if (v < lo || v > hi) {
                return false;
            }
            out = static_cast<int>(v);
            return true;
        };
        LampPlan p;
        if (!count("lights", 1, 256, p.lights)) {
            return bad(fmt::format("lamp '{}': \"lights\" must be an integer in 1..256", name));
        }
        if (!count("specular_samples", 0, 256, p.specularSamples)) {
            return bad(fmt::format("lamp '{}': \"specular_samples\" must be an integer in 0..256",
                                   name));
        }
        if (!count("horizon_directions", 0, 32, p.horizonDirections)) {
            return bad(fmt::format("lamp '{}': \"horizon_directions\" must be an integer in 0..32",
                                   name));
        }
        if (l.contains("walls")) {
            if (!l["walls"].is_boolean()) {
                return bad(fmt::format("lamp '{}': \"walls\" must be true or false", name));
            }
            p.walls = l["walls"].get<bool>();
        }
        p.probeP95 = l.value("probe_de00_p95", 0.0);
        p.probeMax = l.value("probe_de00_max", 0.0);
        p.met = l.value("met_budget", false);
        plan.lamps[name] = p;
    }
    return plan;
}

Expected<RenderPlan> readRenderPlan(const std::filesystem::path& path)
{
    auto text = readInputFile(path, kMaxJsonBytes, "render plan");
    if (!text) {
        return tl::unexpected(text.error());
    }
    return parseRenderPlan(*text, path.string());
}

Expected<void> writeRenderPlan(const std::filesystem::path& path, const RenderPlan& plan)
{
    if (path.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(path.parent_path(), ec);
    }
    return writeOutputFile(path, renderPlanJson(plan), "render plan");
}

Expected<std::string> boothDigest(const std::filesystem::path& boothDir)
{
    std::vector<std::filesystem::path> files;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(boothDir, ec)) {
        const auto ext = e.path().extension().string();
        if (e.is_regular_file() && (ext == ".json" || ext == ".exr")) {
            files.push_back(e.path());
        }
    }
    if (ec || files.empty()) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no booth model to plan for", boothDir.string()));
    }
    std::sort(files.begin(), files.end());
    std::string all;
    for (const auto& f : files) {
        auto bytes = readInputFile(f, kMaxImageBytes, "booth model");
        if (!bytes) {
            return tl::unexpected(bytes.error());
        }
        all += f.filename().string();
        all += *bytes;
    }
    return fmt::format(
            "{:016x}",
            fnv1a64(std::span(reinterpret_cast<const std::uint8_t*>(all.data()), all.size())));
}

std::filesystem::path renderPlanPath(const std::filesystem::path& cacheDir,
                                     const std::string& sceneName,
                                     const std::string& sceneDigest,
                                     const std::string& boothDigest,
                                     const std::string& basis)
{
    return cacheDir /
           fmt::format("plan-{}-{}-{}-{}.json", sceneName, sceneDigest, boothDigest, basis);
}

std::filesystem::path defaultPlanCacheDir()
{
    if (const char* d = std::getenv("REPLICA_PLAN_CACHE"); d != nullptr && *d != '\0') {
        return d;
    }
    if (const char* d = std::getenv("XDG_CACHE_HOME"); d != nullptr && *d != '\0') {
        return std::filesystem::path(d) / "replica" / "plans";
    }
    if (const char* d = std::getenv("HOME"); d != nullptr && *d != '\0') {
        return std::filesystem::path(d) / ".cache" / "replica" / "plans";
    }
    return "/var/tmp/replica-plans";
}

namespace {

// What planning (and checking a plan) needs: the scene, the booth, the observer, the basis per
// light, the digests and the appliance's settings for everything the planner does not choose.
struct PlanInputs {
    pipeline::surface::SurfaceScene scene;
    pipeline::booth::Booth booth;
    pipeline::colour::Observer obs;
    std::string sceneDigest;
    std::string boothDigest;
    std::shared_ptr<pipeline::spectral::AdaptiveEncoder> encoder;
    pipeline::colour::ChannelBasis fixed = pipeline::colour::boxBasis();
    pipeline::shading::RenderSettings base;

    Expected<pipeline::colour::ChannelBasis> basisFor(const pipeline::booth::BoothLight& l) const
    {
        return encoder ? encoder->basisFor(l.spd) : Expected<pipeline::colour::ChannelBasis>(fixed);
    }
};

Expected<PlanInputs> loadPlanInputs(const std::filesystem::path& sceneDir,
                                    const std::filesystem::path& boothDir,
                                    const std::string& basisName)
{
    namespace sh = pipeline::shading;
    PlanInputs in;
    auto scene = pipeline::surface::loadScene(sceneDir);
    if (!scene) {
        return tl::unexpected(scene.error());
    }
    in.scene = std::move(*scene);
    auto booth = pipeline::booth::loadBooth(boothDir);
    if (!booth) {
        return tl::unexpected(booth.error());
    }
    in.booth = std::move(*booth);
    pipeline::scene::placeBoothWalls(in.booth); // their box, as the appliance draws them
    auto obs = pipeline::colour::loadCie1931(dataDir());
    if (!obs) {
        return tl::unexpected(obs.error());
    }
    in.obs = std::move(*obs);
    auto sd = sceneDigest(sceneDir);
    if (!sd) {
        return tl::unexpected(sd.error());
    }
    in.sceneDigest = *sd;
    auto bd = boothDigest(boothDir);
    if (!bd) {
        return tl::unexpected(bd.error());
    }
    in.boothDigest = *bd;
    if (basisName == "adaptive_k6") {
        auto made = pipeline::spectral::AdaptiveEncoder::createDefault(dataDir());
        if (!made) {
            return tl::unexpected(made.error());
        }
        in.encoder = std::make_shared<pipeline::spectral::AdaptiveEncoder>(std::move(*made));
    } else if (basisName != "box6") {
        auto fitted =
                pipeline::colour::loadChannelBasis(dataDir() / "channels" / (basisName + ".csv"));
        if (!fitted) {
            return tl::unexpected(fitted.error());
        }
        in.fixed = std::move(*fitted);
    }
    in.base.specularGrid = sh::defaultSpecularGrid(in.scene);
    in.base.diffuseGrid = sh::defaultDiffuseGrid(in.scene);
    in.base.areaLights = sh::defaultAreaLights(in.scene);
    return in;
}

// The booth's walls under one lamp, for planning: solved at the exact reference's patches (the
// truth) and at the appliance's (what it draws); neither for a booth without walls.
struct PlanWallLight {
    std::optional<pipeline::booth::WallLight> exact;
    std::optional<pipeline::booth::WallLight> realtime;

    pipeline::shading::PlanWalls forPlanner() const
    {
        return {exact ? &*exact : nullptr, realtime ? &*realtime : nullptr};
    }
};

PlanWallLight planWalls(const PlanInputs& in, const pipeline::booth::BoothLight& light)
{
    PlanWallLight w;
    if (in.booth.walls) {
        w.exact = pipeline::reference::solveWalls(*in.booth.walls, light, in.obs);
        pipeline::reference::WallSolveOptions o;
        o.patchM = pipeline::render::kRealtimeWallPatchM;
        w.realtime = pipeline::reference::solveWalls(*in.booth.walls, light, in.obs, o);
    }
    return w;
}

} // namespace

Expected<RenderPlan> computeRenderPlan(const std::filesystem::path& sceneDir,
                                       const std::filesystem::path& boothDir,
                                       const std::string& basisName)
{
    namespace sh = pipeline::shading;
    auto in = loadPlanInputs(sceneDir, boothDir, basisName);
    if (!in) {
        return tl::unexpected(in.error());
    }
    const auto views = sh::probeViews(pipeline::scene::StandModel{}, kPlanProbeWidth,
                                      kPlanProbeHeight, kPlanProbeEyes);
    RenderPlan plan;
    plan.sceneDigest = in->sceneDigest;
    plan.boothDigest = in->boothDigest;
    plan.basis = basisName;
    for (const auto& light : in->booth.lights) {
        auto basis = in->basisFor(light);
        if (!basis) {
            return tl::unexpected(basis.error());
        }
        const sh::ErrorBudget probeBudget{kPlanBudget.p95 * kPlanMargin,
                                          kPlanBudget.max * kPlanMargin};
        const PlanWallLight walls = planWalls(*in, light);
        const sh::Plan p = sh::planRenderViews(in->scene, light, views, in->obs, probeBudget,
                                               in->base, *basis, walls.forPlanner());
        LampPlan lp;
        lp.lights = p.settings.lights;
        lp.specularSamples = in->scene.glossy() ? p.settings.specularSamples : 0;
        lp.horizonDirections = in->scene.flat() ? 0 : p.settings.horizonDirections;
        lp.probeP95 = p.probeError.p95;
        lp.probeMax = p.probeError.max;
        lp.met = p.met;
        lp.walls = p.settings.walls;
        plan.lamps[light.name] = lp;
    }
    return plan;
}

Expected<std::map<std::string, pipeline::reference::FrameError>>
checkRenderPlan(const std::filesystem::path& sceneDir,
                const std::filesystem::path& boothDir,
                const RenderPlan& plan,
                int probeX,
                int probeY,
                int eyes)
{
    namespace sh = pipeline::shading;
    auto in = loadPlanInputs(sceneDir, boothDir, plan.basis);
    if (!in) {
        return tl::unexpected(in.error());
    }
    const auto views = sh::probeViews(pipeline::scene::StandModel{}, probeX, probeY, eyes);
    std::map<std::string, pipeline::reference::FrameError> out;
    for (const auto& light : in->booth.lights) {
        const auto it = plan.lamps.find(light.name);
        if (it == plan.lamps.end()) {
            continue;
        }
        auto basis = in->basisFor(light);
        if (!basis) {
            return tl::unexpected(basis.error());
        }
        sh::RenderSettings s = in->base;
        s.lights = it->second.lights;
        s.specularSamples = it->second.specularSamples;
        s.specularPass = in->scene.glossy();
        s.horizonDirections = it->second.horizonDirections;
        s.reliefPass = !in->scene.flat();
        const PlanWallLight walls = planWalls(*in, light);
        s.walls = walls.exact.has_value() && it->second.walls;
        auto pl = sh::prepareLight(light, in->obs, s.lights, *basis);
        pl.walls = s.walls ? &*walls.realtime : nullptr;
        pipeline::reference::ReferenceOptions ro;
        ro.walls = walls.exact ? &*walls.exact : nullptr;
        const auto ps = sh::prepareScene(in->scene, std::max(s.horizonDirections, 1), 0.01, *basis);
        pipeline::reference::FrameError worst{0.0, 0.0, 0.0};
        for (const auto& v : views) {
            const auto ref = pipeline::reference::renderReference(in->scene, light, v, in->obs, ro);
            const auto e = pipeline::reference::compareFrames(
                    ref, sh::renderRealtime(ps, pl, v, in->obs, s));
            worst.mean = std::max(worst.mean, e.mean);
            worst.p95 = std::max(worst.p95, e.p95);
            worst.max = std::max(worst.max, e.max);
        }
        out[light.name] = worst;
    }
    return out;
}

Expected<RenderPlan> loadOrComputeRenderPlan(const std::filesystem::path& sceneDir,
                                             const std::filesystem::path& boothDir,
                                             const std::string& basis,
                                             const std::filesystem::path& cacheDir,
                                             bool compute)
{
    auto log = logger("planner");
    auto sd = sceneDigest(sceneDir);
    if (!sd) {
        return tl::unexpected(sd.error());
    }
    auto bd = boothDigest(boothDir);
    if (!bd) {
        return tl::unexpected(bd.error());
    }
    const auto path = renderPlanPath(cacheDir, sceneDir.filename().string(), *sd, *bd, basis);
    // The cache first (a plan made here, or edited), then the one shipped with the scene.
    for (const auto& candidate : {path, sceneDir / path.filename()}) {
        std::error_code ec;
        if (!std::filesystem::exists(candidate, ec)) {
            continue;
        }
        auto plan = readRenderPlan(candidate);
        if (!plan) {
            return plan;
        }
        if (plan->sceneDigest != *sd || plan->boothDigest != *bd || plan->basis != basis) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: the plan is for another scene, booth or basis than "
                                         "its name says; delete it and the appliance plans again",
                                         candidate.string()));
        }
        log->info("render plan: {}", candidate.string());
        return plan;
    }
    if (!compute) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("no render plan for {} (basis {}) in {} or with the scene: "
                                     "'replica plan --scene {}' plans it (minutes, once)",
                                     sceneDir.string(), basis, cacheDir.string(),
                                     sceneDir.string()));
    }
    log->info("no render plan for {} at {}: planning every lamp now (minutes, once)",
              sceneDir.string(), path.string());
    auto plan = computeRenderPlan(sceneDir, boothDir, basis);
    if (!plan) {
        return plan;
    }
    if (auto ok = writeRenderPlan(path, *plan); !ok) {
        log->warn("{} (the plan is used for this run only)", ok.error().message);
    } else {
        log->info("render plan written: {}", path.string());
    }
    return plan;
}

} // namespace replica::platform
