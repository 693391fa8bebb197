// Assembling the appliance.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <span>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <hal/replay/replay_source.h>
#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/booth_dimmer_choice.h>
#include <platform/logging.h>
#include <platform/loop/frame_digest.h>
#include <platform/run_config_schema.h>

namespace replica::platform {

pipeline::shading::RenderSettings boothRenderSettings(const RunConfig& config)
{
    pipeline::shading::RenderSettings s;
    s.lights = config.boothLights;
    s.specularSamples = config.specularSamples;
    s.specularGrid = config.specularGrid;
    s.diffuseGrid = config.diffuseGrid;
    s.horizonDirections = config.horizonDirections;
    s.areaLights = config.areaLights != 0;
    s.cacheSlices = config.cacheSlices;
    s.tiltNodesRad = config.tiltNodesDeg * std::numbers::pi / 180.0;
    // The display pass subtracts the screen's flare when asked to (issue 6): then pass 1 must not.
    s.subtractFlare = !config.flareSubtraction;
    return s;
}

namespace {

// The booth renderer's pass 1: the booth model, the scene folder, the settings.
// The geometry rules (docs/architecture.md, Outputs): on a display, a run's frame is the mode's
// size and, with no configured panel size, the panel is the size the display's EDID gives; the
// renderer maps the frame onto the panel, so a surface shows at its physical size where the
// pixels are square.
void applyDisplayGeometry(RunConfig& config, const Output& output, const OutputChoice& choice)
{
    auto log = logger("output");
    const auto display = output.display();
    if (display && choice.frameFromMode) {
        config.width = display->width;
        config.height = display->height;
    }
    if (display && choice.panelFromDisplay) {
        const PanelSize panel =
                resolvePanelSize(std::nullopt, display->edidSize, config.stand.panelWidthM,
                                 config.stand.panelHeightM);
        config.stand.panelWidthM = panel.widthM;
        config.stand.panelHeightM = panel.heightM;
        if (panel.source == "edid") {
            log->info("panel {:.0f}x{:.0f} mm from the EDID of {}", panel.widthM * 1000.0,
                      panel.heightM * 1000.0, display->connector);
        } else {
            log->warn("{} gives no physical size: the panel is taken as {:.0f}x{:.0f} mm; set "
                      "its active area with --panel-size-mm",
                      display->connector, panel.widthM * 1000.0, panel.heightM * 1000.0);
        }
    }
    const PanelSize panel{config.stand.panelWidthM, config.stand.panelHeightM, ""};
    if (const double e = pixelAspectError(panel, config.width, config.height); e > 0.02) {
        log->warn("a {}x{} frame on a {:.0f}x{:.0f} mm panel has pixels {:.1f}% off square: "
                  "surfaces show stretched; check the panel size and the mode",
                  config.width, config.height, config.stand.panelWidthM * 1000.0,
                  config.stand.panelHeightM * 1000.0, 100.0 * e);
    }
}

// The booth pass's setup: the scene folder (its digest checked against a recording's), the
// booth, the bases, and the counts chosen for the scene (recorded in 'config').
Expected<pipeline::render::BoothSceneSetup>
boothSceneSetup(RunConfig& config,
                const pipeline::booth::Booth& booth,
                const pipeline::colour::ChannelBasis& basis,
                const pipeline::colour::Observer& observer,
                std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> adaptive)
{
    const auto dir = resolveSceneDir(config.sceneDir);
    auto digest = sceneDigest(dir);
    if (!digest) {
        return tl::unexpected(digest.error());
    }
    if (auto same = checkAndRecordDigest(config.sceneDigest, *digest, "scene", dir.string());
        !same) {
        return tl::unexpected(same.error());
    }
    auto scene = pipeline::surface::loadScene(dir);
    if (!scene) {
        return tl::unexpected(scene.error());
    }
    config.scene = scene->name;
    pipeline::render::BoothSceneSetup setup;
    setup.booth = booth;
    setup.scene = std::move(*scene);
    setup.basis = basis;
    setup.adaptive = std::move(adaptive);
    setup.observer = observer;
    setup.stand = config.stand;
    // The counts chosen for the scene, recorded.
    if (config.specularSamples == kAutoSpecularSamples) {
        config.specularSamples = pipeline::shading::defaultSpecularSamples(setup.scene);
    }
    if (config.specularGrid == kAutoSpecularGrid) {
        config.specularGrid = pipeline::shading::defaultSpecularGrid(setup.scene);
    }
    if (config.diffuseGrid == kAutoDiffuseGrid) {
        config.diffuseGrid = pipeline::shading::defaultDiffuseGrid(setup.scene);
    }
    if (config.areaLights == kAutoAreaLights) {
        config.areaLights = pipeline::shading::defaultAreaLights(setup.scene) ? 1 : 0;
    }
    setup.settings = boothRenderSettings(config);
    return setup;
}

// The planner in the loop: the scene's cached plan (computed once when missing), recorded in
// config.plannedLamps, and each planned lamp's counts in the setup.
Expected<void> applyRenderPlan(RunConfig& config, pipeline::render::BoothSceneSetup& setup)
{
    if (config.planner && config.plannedLamps.empty()) {
        auto plan = loadOrComputeRenderPlan(
                resolveSceneDir(config.sceneDir), resolveSceneDir(config.boothDir), config.basis,
                config.plannerCache.empty() ? defaultPlanCacheDir()
                                            : std::filesystem::path(config.plannerCache),
                config.planIfMissing);
        if (!plan && !config.planIfMissing && plan.error().code == ErrorCode::NotFound) {
            // 'replica run''s default on a scene nobody planned: the fixed rules, said once.
            logger("planner")->info("{}; the fixed rules until then", plan.error().message);
        } else if (!plan) {
            return tl::unexpected(plan.error());
        } else {
            for (const auto& lamp : setup.booth.lights) {
                const auto it = plan->lamps.find(lamp.name);
                if (it != plan->lamps.end()) {
                    config.plannedLamps[lamp.name] = it->second;
                }
            }
        }
    }
    for (const auto& [name, p] : config.plannedLamps) {
        pipeline::render::LampSettings ls;
        ls.lights = p.lights;
        ls.specularSamples = p.specularSamples;
        ls.horizonDirections = p.horizonDirections;
        ls.walls = p.walls;
        setup.perLamp[name] = ls;
        logger("planner")->info("lamp {}: {} lights, {} specular samples, {} horizon directions{}",
                                name, p.lights, p.specularSamples, p.horizonDirections,
                                setup.booth.walls ? (p.walls ? ", the walls' light" : ", no walls")
                                                  : "");
    }
    return {};
}

// The index of the booth's lamp named exactly 'name' (a state's lampIndex), -1 when none is.
int lampIndex(const pipeline::booth::Booth& booth, const std::string& name)
{
    const auto& lamps = booth.lights;
    const auto it =
            std::find_if(lamps.begin(), lamps.end(), [&](const auto& l) { return l.name == name; });
    return it == lamps.end() ? -1 : static_cast<int>(it - lamps.begin());
}

// Milliseconds since 'start', for the start-up's debug lines.
double startupMs(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
}

// The booth pass, its shading passes compiled before the first frame unless --no-warm-up.
Expected<std::shared_ptr<pipeline::render::BoothScenePass>>
createBoothScene(const RunConfig& config, pipeline::render::BoothSceneSetup setup)
{
    const auto start = std::chrono::steady_clock::now();
    auto pass = pipeline::render::BoothScenePass::create(std::move(setup));
    if (!pass) {
        return tl::unexpected(pass.error());
    }
    logger("render")->debug("booth pass made in {:.0f} ms ({} shading pass(es), one made now)",
                            startupMs(start), (*pass)->variantCount());
    // --no-warm-up skips it (frames are the same either way): under software emulation (the boot
    // test's TCG guest) compiling every pass before the first frame takes minutes.
    if (!config.warmUp) {
        logger("render")->info("no warm-up: shading passes compile at their first use");
    } else if (config.warmUpAfterFirstFrame) {
        logger("render")->info("the first frame compiles the shading pass it draws; the other "
                               "{} compile after it",
                               (*pass)->variantCount() - 1);
    } else {
        // Each lamp's pass compiled now, not at the loop's first switch to it.
        auto ms = (*pass)->warmUp(config.width, config.height);
        if (!ms) {
            return tl::unexpected(ms.error());
        }
        logger("render")->info("{} shading pass(es) warmed up in {:.0f} ms",
                               (*pass)->variantCount(), *ms);
    }
    return std::shared_ptr<pipeline::render::BoothScenePass>(std::move(*pass));
}

Expected<std::shared_ptr<pipeline::render::BoothScenePass>>
makeBoothScene(RunConfig& config,
               const pipeline::booth::Booth& booth,
               const pipeline::colour::ChannelBasis& basis,
               const pipeline::colour::Observer& observer,
               std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> adaptive,
               const pipeline::display::DisplayModel& displayModel)
{
    auto setup = boothSceneSetup(config, booth, basis, observer, std::move(adaptive));
    if (!setup) {
        return tl::unexpected(setup.error());
    }
    if (auto ok = applyRenderPlan(config, *setup); !ok) {
        return tl::unexpected(ok.error());
    }
    // The default lamp is what the first frame shows until the first spectrum: its pass is the
    // one made before the first frame (the direct-sensor mode draws variant 0's).
    if (config.light != kLightDirect) {
        setup->firstLamp = lampIndex(setup->booth, config.defaultLamp);
    }
    if (config.boothDimmerAuto) {
        const auto start = std::chrono::steady_clock::now();
        // Prepared once: each lamp's probe views and then the pass's first variant copy its
        // horizons (the painting's took 0.4 s each, four times before the first frame).
        setup->prepared = std::make_shared<const pipeline::shading::PreparedScene>(
                pipeline::shading::prepareScene(setup->scene,
                                                std::max(setup->settings.horizonDirections, 1),
                                                0.01, setup->basis));
        logger("booth")->debug("relief prepared in {:.0f} ms", startupMs(start));
        chooseBoothDimmer(config, *setup, displayModel);
        logger("booth")->debug("booth dimmer (auto) chosen in {:.0f} ms", startupMs(start));
    }
    setup->luminanceScale = config.boothDimmer;
    if (config.boothDimmer != 1.0) {
        for (auto& light : setup->booth.lights) {
            for (double& t : light.luminance.cdM2) {
                t *= config.boothDimmer;
            }
        }
    }
    return createBoothScene(config, std::move(*setup));
}

// The display pass's setup from the configuration: the profile (checked against the digest a
// recording holds) or the nominal model.
Expected<pipeline::render::DisplayPassSetup> displaySetup(RunConfig& config, std::string& id)
{
    namespace pd = pipeline::display;
    pipeline::render::DisplayPassSetup d;
    if (config.display == kUncalibratedDisplay) {
        d.model = pd::nominalDisplayModel(kUncalibratedDisplay, config.displayPeakCdM2,
                                          config.displayBlackCdM2);
    } else {
        std::filesystem::path path(config.display);
        if (path.is_relative()) {
            path = dataDir() / path;
        }
        auto read = readInputFile(path, kMaxJsonBytes, "display profile");
        if (!read) {
            if (read.error().code != ErrorCode::NotFound) {
                return tl::unexpected(read.error());
            }
            return makeError(ErrorCode::NotFound, missingDisplayProfileMessage(path.string()));
        }
        const std::string& bytes = *read;
        const std::string digest = fmt::format(
                "{:016x}", fnv1a64(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                             bytes.size())));
        if (auto same = checkAndRecordDigest(config.displayDigest, digest, "display profile",
                                             path.string());
            !same) {
            return tl::unexpected(same.error());
        }
        auto model = pd::profileFromJson(bytes, path.string());
        if (!model) {
            return tl::unexpected(model.error());
        }
        d.model = std::move(*model);
    }
    d.method = config.displayInverse == "lut3d" ? pipeline::render::InverseMethod::Lut3d
                                                : pipeline::render::InverseMethod::Analytic;
    d.gamut = config.gamutMapping == "clip" ? pd::GamutMode::Clip : pd::GamutMode::HueKeeping;
    d.viewingCompensation = config.viewingCompensation;
    d.flareSubtraction = config.flareSubtraction;
    d.falseColour = config.falseColour;
    id = displayProfileId(config, d.model.name);
    return d;
}

} // namespace

namespace {

// The booth, scene and basis a configuration names must be ones this build has.
Expected<void> checkBuildHas(const RunConfig& config)
{
    const std::vector<std::string> bases = pipeline::spectral::channelBasisNames();
    const bool knownBasis = std::find(bases.begin(), bases.end(), config.basis) != bases.end();
    if (config.booth != "replica-booth-1" || !knownBasis) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("unknown booth '{}' or basis '{}' (this build has "
                                     "replica-booth-1, and bases {})",
                                     config.booth, config.basis, fmt::join(bases, ", ")));
    }
    return {};
}

// The channel basis the surface is drawn in, and with adaptive_k6 the encoder that re-encodes it
// for each light (its general basis then): adaptive_k6 (the default), box6 (built in; what the
// first recordings used) or one fitted by 'replica spectral fit' under data/channels/
// (docs/accuracy.md).
struct Encoding {
    pipeline::colour::ChannelBasis basis = pipeline::colour::boxBasis();
    std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> adaptive;
};

Expected<Encoding> loadEncoding(const RunConfig& config, const std::string& dir)
{
    Encoding e;
    if (config.basis == kAdaptiveBasis) {
        auto made = pipeline::spectral::AdaptiveEncoder::createDefault(dir);
        if (!made) {
            return tl::unexpected(made.error());
        }
        e.adaptive = std::make_shared<const pipeline::spectral::AdaptiveEncoder>(std::move(*made));
        e.basis = e.adaptive->generalBasis();
    } else if (config.basis != "box6") {
        auto fitted = pipeline::colour::loadChannelBasis(std::filesystem::path(dir) / "channels" /
                                                         (config.basis + ".csv"));
        if (!fitted) {
            return tl::unexpected(fitted.error());
        }
        e.basis = std::move(*fitted);
    }
    return e;
}

// The state stage (state/): the light, eye and tilt estimators, from the booth data and the
// configuration alone (nothing of the renderer): the lamps and their spectra are the booth's.
Expected<std::unique_ptr<state::SceneEstimator>>
makeStateStage(const RunConfig& config,
               const pipeline::booth::Booth& booth,
               const Encoding& encoding,
               const pipeline::colour::Observer& observer,
               const std::string& dir)
{
    auto calibration = pipeline::spectral::loadSpectrometerCalibration(
            std::filesystem::path(dir) / config.spectrometerCalibration);
    if (!calibration) {
        return tl::unexpected(calibration.error());
    }
    state::SceneEstimatorSetup setup;
    setup.light.booth = booth;
    setup.light.calibration = *calibration;
    setup.light.chain = config.sensing;
    setup.light.instrument = config.instrument;
    setup.light.forceDirect = config.light == kLightDirect;
    setup.light.directCdM2PerY = config.directCdM2PerY;
    setup.light.observer = observer;
    // The re-encode decision and the diffuse term's sliced refresh are state.
    setup.light.adaptive = encoding.adaptive;
    setup.tilt.cacheSlices = config.cacheSlices;
    setup.tilt.tiltNodesRad = config.tiltNodesDeg * std::numbers::pi / 180.0;
    setup.eye.trackerInBooth = config.trackerInBooth;
    setup.eye.defaultEyeM = config.defaultEyeM;
    setup.tilt.defaultTiltRad = config.defaultTiltRad;
    if (!config.defaultLamp.empty()) {
        const int lamp = lampIndex(booth, config.defaultLamp);
        if (lamp < 0) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("default lamp '{}' is not a lamp of booth '{}' ({})",
                                         config.defaultLamp, config.booth, booth.names()));
        }
        setup.light.defaultLamp = lamp;
    }
    auto estimator = state::SceneEstimator::create(std::move(setup));
    if (!estimator) {
        return tl::unexpected(estimator.error());
    }
    return std::make_unique<state::SceneEstimator>(std::move(*estimator));
}

// The renderer, in the output's GL context: the booth pass and the display pass.
Expected<void> makeRenderer(Appliance& app,
                            pipeline::render::DisplayPassSetup display,
                            const Encoding& encoding,
                            const pipeline::colour::Observer& observer)
{
    const RunConfig& config = app.config;
    pipeline::render::GlesRendererSetup setup;
    setup.width = config.width;
    setup.height = config.height;
    setup.stand = config.stand;
    setup.observer = observer;
    app.displayWhiteXyz = display.model.whiteXyz();
    app.displayModel = display.model;
    setup.display = std::move(display);
    auto boothScene = makeBoothScene(app.config, app.booth, encoding.basis, observer,
                                     encoding.adaptive, setup.display.model);
    if (!boothScene) {
        return tl::unexpected(boothScene.error());
    }
    app.boothScene = *boothScene;
    setup.boothScene = std::move(*boothScene);
    const auto start = std::chrono::steady_clock::now();
    auto renderer = pipeline::render::createGlesRenderer(std::move(setup));
    if (!renderer) {
        return tl::unexpected(renderer.error());
    }
    logger("render")->debug("renderer (display pass) made in {:.0f} ms", startupMs(start));
    app.renderer = std::move(*renderer);
    return {};
}

} // namespace

Expected<std::unique_ptr<Appliance>> buildAppliance(const RunConfig& configIn,
                                                    const OutputChoice& outputChoice)
{
    // In the order the data flows: the booth data, the state stage, then the output (the display
    // and the GL context the renderer draws in) and the renderer.
    RunConfig config = configIn;
    if (auto ok = checkBuildHas(config); !ok) {
        return tl::unexpected(ok.error());
    }
    std::string displayId;
    auto display = displaySetup(config, displayId);
    if (!display) {
        return tl::unexpected(display.error());
    }
    const std::string dir = dataDir().string();
    auto app = std::make_unique<Appliance>();
    app->displayProfileId = displayId;
    auto booth = loadRunBooth(config);
    if (!booth) {
        return tl::unexpected(booth.error());
    }
    app->booth = *booth;
    auto observer = pipeline::colour::loadCie1931(dir);
    if (!observer) {
        return tl::unexpected(observer.error());
    }
    auto encoding = loadEncoding(config, dir);
    if (!encoding) {
        return tl::unexpected(encoding.error());
    }
    auto estimator = makeStateStage(config, app->booth, *encoding, *observer, dir);
    if (!estimator) {
        return tl::unexpected(estimator.error());
    }
    app->sceneEstimator = std::move(*estimator);

    const auto outputStart = std::chrono::steady_clock::now();
    auto output =
            outputChoice.kind == "kms" ? createKmsOutput(outputChoice.kms) : createHeadlessOutput();
    if (!output) {
        return tl::unexpected(output.error());
    }
    logger("output")->debug("output and GL context up in {:.0f} ms", startupMs(outputStart));
    app->output = std::move(*output);
    applyDisplayGeometry(config, *app->output, outputChoice);
    app->config = config;
    if (auto ok = makeRenderer(*app, std::move(*display), *encoding, *observer); !ok) {
        return tl::unexpected(ok.error());
    }
    return app;
}

Expected<void> restoreStateAtStart(Appliance& appliance, const std::string& configJson)
{
    const auto config = nlohmann::json::parse(configJson, nullptr, false);
    if (config.is_discarded() || !config.is_object() || !config.contains(kStateAtStartKey)) {
        return {};
    }
    if (auto ok = appliance.sceneEstimator->restore(config[kStateAtStartKey]); !ok) {
        return makeError(ok.error().code, fmt::format("the run configuration's {}: {}",
                                                      kStateAtStartKey, ok.error().message));
    }
    return {};
}

} // namespace replica::platform
