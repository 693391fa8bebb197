// 'replica render': one frame of absolute XYZ (cd/m^2) for a scene, light, eye and tilt, as
// OpenEXR.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/base/printable.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/image/exr.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/render/booth_shaders.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <pipeline/surface/surface_scene.h>
#include <pipeline/tuning/planner.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/output/display_geometry.h>
#include <platform/output/output.h>

namespace replica::platform {
namespace {

struct RenderArgs {
    std::string scene;
    std::string booth;
    std::string light;
    std::string eye = "0,0.45,0.60";
    double tilt = 30.0;
    std::string size = "192x120";
    bool reference = false;
    bool plan = false;
    bool gl = false;
    int lights = 32;
    int samples = kAutoSpecularSamples;   // as the appliance chooses it for the scene
    int specularGrid = kAutoSpecularGrid; // as the appliance chooses it for the scene
    int diffuseGrid = kAutoDiffuseGrid;   // likewise
    double lodBias = pipeline::shading::kDefaultSpecularLodBias;
    bool trilinear = false;
    bool pointLights = false;
    int horizonDirections = 8;
    std::string basis = "adaptive_k6";
    std::string out;
    bool json = false;
    bool shadingOnly = false;
};

// --shading-only: every texel a neutral white (reflectance 0.8 at every wavelength), so that the
// frame shows only the shading and shadowing of the relief and the gloss (the paper's Fig. 3).
constexpr double kShadingOnlyReflectance = 0.8;

void neutralise(pipeline::surface::SurfaceScene& scene)
{
    for (auto& p : scene.palette) {
        p = pipeline::colour::Spectrum::constant(kShadingOnlyReflectance);
    }
    std::fill(scene.shade.begin(), scene.shade.end(), 1.0f);
}

// The channel basis by name: adaptive_k6 is built for the light rendered (the appliance's
// default: exact for that light), the others are fixed (box6 built in, the rest fitted files under
// data/channels/).
Expected<pipeline::colour::ChannelBasis> namedBasis(const std::string& name,
                                                    const pipeline::colour::Spectrum& light)
{
    using namespace pipeline;
    if (name == "adaptive_k6") {
        auto encoder = spectral::AdaptiveEncoder::createDefault(dataDir());
        if (!encoder) {
            return tl::unexpected(encoder.error());
        }
        return encoder->basisFor(light);
    }
    if (name == "box6") {
        return colour::boxBasis();
    }
    return colour::loadChannelBasis(dataDir() / "channels" / (name + ".csv"));
}

bool parseTriple(const std::string& s, glm::dvec3& v)
{
    char c1 = 0, c2 = 0;
    std::istringstream in(s);
    in >> v.x >> c1 >> v.y >> c2 >> v.z;
    return in && c1 == ',' && c2 == ',' && in.peek() == std::char_traits<char>::eof();
}

bool parseSize(const std::string& s, int& w, int& h)
{
    const auto size = parsePixelSize(s); // the one WxH parser, each side checked before narrowing
    if (!size || size->first <= 0 || size->second <= 0 || size->first > 8192 ||
        size->second > 8192) {
        return false;
    }
    w = static_cast<int>(size->first);
    h = static_cast<int>(size->second);
    return true;
}

int fail(int code, const std::string& msg)
{
    // Messages quote names from the booth's and scene's files: escapes shown, never run.
    std::fprintf(stderr, "replica render: %s\n", printable(msg, std::string::npos, true).c_str());
    return code;
}

// The real-time model's settings from the options (the scene's defaults where not given).
pipeline::shading::RenderSettings settingsFromArgs(const RenderArgs& a,
                                                   const pipeline::surface::SurfaceScene& scene)
{
    using namespace pipeline;
    shading::RenderSettings settings;
    settings.lights = a.lights;
    settings.specularSamples = a.samples > 0 ? a.samples : shading::defaultSpecularSamples(scene);
    settings.horizonDirections = a.horizonDirections;
    settings.specularGrid =
            a.specularGrid >= 0 ? a.specularGrid : shading::defaultSpecularGrid(scene);
    settings.diffuseGrid = a.diffuseGrid >= 0 ? a.diffuseGrid : shading::defaultDiffuseGrid(scene);
    settings.specularLodBias = a.lodBias;
    settings.specularNearestLevel = !a.trilinear;
    settings.areaLights = !a.pointLights;
    return settings;
}

// The frame as an absolute-XYZ OpenEXR file, with what made it in its header.
Expected<void> writeXyzExr(const pipeline::shading::XyzFrame& frame,
                           const RenderArgs& a,
                           const std::string& mode,
                           const std::string& sceneName)
{
    using namespace pipeline;
    image::ChannelImage img;
    img.width = frame.width;
    img.height = frame.height;
    img.names = {"X", "Y", "Z"};
    img.planes.assign(3, std::vector<float>(frame.xyz.size()));
    for (std::size_t k = 0; k < frame.xyz.size(); ++k) {
        for (std::size_t c = 0; c < 3; ++c) {
            img.planes[c][k] = static_cast<float>(frame.xyz[k][static_cast<int>(c)]);
        }
    }
    if (auto ok = image::writeExr(
                a.out, img,
                {{"units",
                  "absolute CIE 1931 XYZ, cd/m^2 (panel emission after screen-flare subtraction)"},
                 {"renderer", mode},
                 {"light", a.light},
                 {"scene", sceneName}});
        !ok) {
        return ok;
    }
    return {};
}

// What the render did, for --json and the summary line.
nlohmann::json renderSummary(const RenderArgs& a,
                             const std::string& mode,
                             double ms,
                             const pipeline::shading::XyzFrame& frame,
                             const pipeline::shading::RenderSettings& settings,
                             const pipeline::surface::SurfaceScene& scene,
                             const std::string& basisName,
                             const pipeline::shading::Plan& plan)
{
    nlohmann::json j{{"out", a.out},
                     {"mode", mode},
                     {"ms", ms},
                     {"width", frame.width},
                     {"height", frame.height},
                     {"white_y_cdm2", frame.whiteY},
                     {"flare_clamped", frame.flareClamped},
                     {"eye_behind_pixels", frame.eyeBehindPixels}};
    if (!a.reference) {
        j["lights"] = settings.lights;
        j["basis"] = basisName;
        j["specular_samples"] =
                scene.glossy() && settings.specularPass ? settings.specularSamples : 0;
        j["specular_grid"] = scene.glossy() && settings.specularPass ? settings.specularGrid : 0;
        j["diffuse_grid"] = scene.flat() || !settings.reliefPass ? settings.diffuseGrid : 0;
        j["specular_lod_bias"] = settings.specularLodBias;
        j["specular_nearest_level"] = settings.specularNearestLevel;
        j["area_lights"] = settings.areaLights;
        j["horizon_directions"] =
                !scene.flat() && settings.reliefPass ? settings.horizonDirections : 0;
        if (a.plan) {
            j["plan_met_budget"] = plan.met;
            j["plan_probe_de00_p95"] = plan.probeError.p95;
            j["plan_skipped"] = plan.skipped;
        }
    }
    return j;
}

// One frame of the GL pass (in the current context).
Expected<pipeline::shading::XyzFrame> renderGl(const pipeline::shading::PreparedScene& ps,
                                               const pipeline::shading::PreparedLight& pl,
                                               const pipeline::shading::View& view,
                                               const pipeline::colour::Observer& obs,
                                               const pipeline::shading::RenderSettings& settings)
{
    using namespace pipeline;
    auto pass = render::BoothShadingPass::create(ps, settings, obs);
    if (!pass) {
        return tl::unexpected(pass.error());
    }
    if (auto ok = (*pass)->setLight(pl); !ok) {
        return tl::unexpected(ok.error());
    }
    return render::renderBoothFrame(**pass, pl, view);
}

// The frame 'a' asks for: the exact reference, or the real-time model on the CPU or the GL pass,
// planned or not, and how long it took.
struct RenderedFrame {
    pipeline::shading::XyzFrame frame;
    pipeline::shading::RenderSettings settings;
    std::string mode;
    pipeline::shading::Plan plan;
    double ms = 0.0;
};

Expected<RenderedFrame> renderFrame(const RenderArgs& a,
                                    const pipeline::surface::SurfaceScene& scene,
                                    const pipeline::booth::BoothLight& light,
                                    const pipeline::shading::View& view,
                                    const pipeline::colour::Observer& obs,
                                    const pipeline::colour::ChannelBasis& basis)
{
    using namespace pipeline;
    const auto t0 = std::chrono::steady_clock::now();
    RenderedFrame r{{}, settingsFromArgs(a, scene), "realtime-cpu", {}, 0.0};
    if (a.reference) {
        r.mode = "reference";
        r.frame = reference::renderReference(scene, light, view, obs);
    } else {
        if (a.plan) {
            r.plan = shading::planRender(scene, light, view, obs, {}, 32, 20, basis);
            r.settings = r.plan.settings;
            r.settings.areaLights = !a.pointLights;
        }
        const auto pl = shading::prepareLight(light, obs, r.settings.lights, basis);
        const auto ps = shading::prepareScene(scene, std::max(r.settings.horizonDirections, 1),
                                              0.01, basis);
        if (a.gl) {
            r.mode = "realtime-gles";
            auto f = renderGl(ps, pl, view, obs, r.settings);
            if (!f) {
                return tl::unexpected(f.error());
            }
            r.frame = std::move(*f);
        } else {
            r.frame = shading::renderRealtime(ps, pl, view, obs, r.settings);
        }
        if (a.plan) {
            r.mode += ", planned";
        }
    }
    r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

int runRender(const RenderArgs& a)
{
    using namespace pipeline;
    shading::View view;
    if (!parseTriple(a.eye, view.eye)) {
        return fail(kExitUsage,
                    fmt::format("--eye '{}' must be X,Y,Z in metres (booth frame)", a.eye));
    }
    if (!parseSize(a.size, view.pixelsX, view.pixelsY)) {
        return fail(kExitUsage, fmt::format("--size '{}' must be WxH, e.g. 960x600", a.size));
    }
    auto booth = booth::loadBooth(a.booth.empty() ? dataDir() / "booth"
                                                  : std::filesystem::path(a.booth));
    if (!booth) {
        return fail(kExitFailure, booth.error().message);
    }
    const booth::BoothLight* light = booth->find(a.light);
    if (light == nullptr) {
        return fail(kExitUsage, fmt::format("--light '{}' is not in the booth; choose one of: {}",
                                            a.light, booth->names()));
    }
    auto scene = surface::loadScene(a.scene);
    if (!scene) {
        return fail(kExitFailure, scene.error().message);
    }
    if (a.shadingOnly) {
        neutralise(*scene);
    }
    auto obs = colour::loadCie1931(dataDir());
    if (!obs) {
        return fail(kExitFailure, obs.error().message);
    }
    view.panel = scene::panelPose(scene::degreesToRadians(a.tilt));
    // The channel basis (docs/accuracy.md), for the CPU model and the GL pass alike.
    auto basis = namedBasis(a.basis, light->spd);
    if (!basis) {
        return fail(kExitFailure, basis.error().message);
    }
    if (a.gl && !a.reference && a.lights > render::kBoothMaxLights) {
        return fail(kExitUsage,
                    fmt::format("--lights {}: the GL pass holds at most {} lights; ask "
                                "for {} or fewer, or render without --gl",
                                a.lights, render::kBoothMaxLights, render::kBoothMaxLights));
    }
    std::unique_ptr<platform::Output> output;
    if (a.gl && !a.reference) {
        auto out = platform::createHeadlessOutput();
        if (!out) {
            return fail(kExitFailure, out.error().message);
        }
        output = std::move(*out);
    }

    auto rendered = renderFrame(a, *scene, *light, view, *obs, *basis);
    if (!rendered) {
        return fail(kExitFailure, rendered.error().message);
    }
    const auto& [frame, settings, mode, plan, ms] = *rendered;
    if (frame.nonFinite != 0) {
        return fail(kExitFailure,
                    fmt::format("{} pixels were not finite; this is a bug, please report it",
                                frame.nonFinite));
    }
    if (auto ok = writeXyzExr(frame, a, mode, scene->name); !ok) {
        return fail(kExitFailure, ok.error().message);
    }
    const nlohmann::json j = renderSummary(a, mode, ms, frame, settings, *scene, basis->name, plan);
    if (a.json) {
        std::printf("%s\n", j.dump().c_str());
    } else {
        std::printf("%s: %dx%d %s frame in %.0f ms; white %.1f cd/m^2; flare clamps %ld; "
                    "eye-behind pixels %ld\n",
                    a.out.c_str(), frame.width, frame.height, mode.c_str(), ms, frame.whiteY,
                    frame.flareClamped, frame.eyeBehindPixels);
    }
    return frame.eyeBehindPixels > 0 ? kExitLossy : kExitOk;
}

} // namespace

void registerRenderCommand(CLI::App& app, int& exitCode)
{
    auto args = std::make_shared<RenderArgs>();
    CLI::App* cmd = app.add_subcommand(
            "render",
            "render one frame of a scene under a booth light to an absolute-XYZ OpenEXR (cd/m^2)");
    cmd->add_option("--scene", args->scene, "scene folder (with scene.json)")->required();
    cmd->add_option("--light", args->light,
                    "booth light name (tungsten, d50, d65 in the shipped booth)")
            ->required();
    cmd->add_option("--booth", args->booth,
                    "booth model folder, e.g. one 'replica booth build' made from a site's "
                    "captures (docs/booth-capture.md); default: the shipped data/booth");
    cmd->add_option("--eye", args->eye, "eye position X,Y,Z in metres, booth frame")
            ->capture_default_str();
    cmd->add_option("--tilt", args->tilt,
                    "panel tilt in degrees (0 = upright, positive leans back)")
            ->capture_default_str();
    cmd->add_option("--size", args->size, "output size WxH in pixels")->capture_default_str();
    cmd->add_flag("--reference", args->reference, "use the exact CPU reference integrator (slow)");
    cmd->add_flag("--gl", args->gl,
                  "render with the GLES 3.1 pass through surfaceless EGL (what the appliance runs) "
                  "instead of its CPU model");
    cmd->add_flag("--plan", args->plan,
                  "let the planner pick the cheapest setting meeting dE00 p95 <= 1");
    cmd->add_option("--lights", args->lights,
                    "median-cut regions of the light (at most 256 with --gl)")
            ->capture_default_str()
            ->check(CLI::Range(1, 4096));
    cmd->add_option("--samples", args->samples,
                    "specular FIS samples per pixel (or grid node); -1: as the appliance chooses "
                    "(8 on relief, 24 on a flat surface)")
            ->capture_default_str()
            ->check(CLI::Range(kAutoSpecularSamples, 1024) & !CLI::IsMember({0}));
    cmd->add_option("--specular-grid", args->specularGrid,
                    "texels between the nodes the specular term is shaded at, then interpolated; "
                    "0: per pixel; -1: as the appliance chooses (8 on a flat surface; on relief "
                    "the most the surface's turn per texel allows against its gloss lobe, per "
                    "pixel where it turns fast)")
            ->capture_default_str()
            ->check(CLI::Range(kAutoSpecularGrid, 256));
    cmd->add_option("--diffuse-grid", args->diffuseGrid,
                    "texels between the nodes eq. (1) is summed at (on relief with each node's "
                    "facet and horizons), then interpolated; 0: per pixel; -1: as the appliance "
                    "chooses (8 on a flat surface; on relief the most the surface's turn per "
                    "texel allows against the horizon test's softness, per pixel where it turns "
                    "fast)")
            ->capture_default_str()
            ->check(CLI::Range(kAutoDiffuseGrid, 256));
    cmd->add_flag("--specular-trilinear", args->trilinear,
                  "read each specular sample between the two mip levels around its own instead "
                  "of from the nearest one (slower)");
    cmd->add_flag(
            "--point-lights", args->pointLights,
            "light the diffuse term from each median-cut region's centroid as a point light "
            "instead of from the region's area (an approximation of the area's exact integral)");
    cmd->add_option("--specular-lod-bias", args->lodBias,
                    "added to each specular sample's mip level: more blurs the light under each "
                    "sample, less aliases it (docs/rendering.md measures the choice)")
            ->capture_default_str()
            ->check(CLI::Range(-pipeline::shading::kMaxSpecularLodBias,
                               pipeline::shading::kMaxSpecularLodBias));
    cmd->add_option("--horizon-directions", args->horizonDirections, "horizon map azimuths")
            ->capture_default_str()
            ->check(CLI::Range(1, 64));
    cmd->add_option("--basis", args->basis,
                    "channel basis: adaptive_k6 (encoded for the light: the appliance's default), "
                    "replica_k6, general_k6, pca6, box6 (docs/accuracy.md)")
            ->check(CLI::IsMember(pipeline::spectral::channelBasisNames()))
            ->capture_default_str();
    cmd->add_option("--out", args->out, "output .exr")
            ->required()
            ->check(CLI::Validator(
                    [](std::string& s) {
                        // The image is OpenEXR: a .png (or any other) name would hold EXR bytes.
                        return std::filesystem::path(s).extension() == ".exr"
                                       ? std::string()
                                       : "'" + s + "' must end in .exr (render writes OpenEXR)";
                    },
                    "", "FILE.exr"));
    cmd->add_flag("--json", args->json, "print the summary as JSON");
    cmd->add_flag("--shading-only", args->shadingOnly,
                  "replace the surface's colour by a neutral white (reflectance 0.8 at every "
                  "wavelength): only the shading and shadowing of its relief and gloss show (the "
                  "paper's Fig. 3)");
    cmd->callback([args, &exitCode] { exitCode = runRender(*args); });
}

} // namespace replica::platform
