// The automatic booth dimmer's choice (booth_dimmer_choice.h).
#include <algorithm>
#include <array>
#include <tuple>

#include <fmt/format.h>

#include <pipeline/base/parallel_for.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/shading/realtime_model.h>
#include <platform/booth_dimmer.h>
#include <platform/booth_dimmer_choice.h>
#include <platform/logging.h>

namespace replica::platform {
namespace {

// The views the automatic dimmer probes: the stand's tilts of 0, 15, 30, 45 and 60 degrees, each
// seen from the default eye and from 0.4 m to either side of it (a visitor walking past: the
// simulated scenario's walk), on a 32 x 20 probe frame.
constexpr std::array<double, 5> kDimmerTiltsDeg{0.0, 15.0, 30.0, 45.0, 60.0};
constexpr std::array<double, 3> kDimmerEyeOffsetsM{-0.4, 0.0, 0.4};

// Each probe view of one lamp (the CPU model, the lamp's own adaptive basis), as the display pass
// meets it.
std::vector<DimmerView> dimmerViews(const RunConfig& config,
                                    const pipeline::render::BoothSceneSetup& setup,
                                    const pipeline::booth::BoothLight& light)
{
    namespace sh = pipeline::shading;
    pipeline::colour::ChannelBasis basis = setup.basis;
    if (setup.adaptive) {
        if (auto b = setup.adaptive->basisFor(light.spd)) {
            basis = std::move(*b);
        }
    }
    // The relief's normals and horizons prepared once for every lamp (makeBoothScene), the
    // palette in the lamp's basis.
    const auto ps = setup.prepared ? sh::reprojectScene(*setup.prepared, setup.scene, basis)
                                   : sh::prepareScene(setup.scene,
                                                      std::max(setup.settings.horizonDirections, 1),
                                                      0.01, basis);
    const auto pl = sh::prepareLight(light, setup.observer, setup.settings.lights, basis);
    // The views share nothing but the prepared scene and light: drawn on every core (start-up
    // waits for them), each into its own slot, so the choice is the same on any machine.
    std::vector<DimmerView> views(kDimmerTiltsDeg.size() * kDimmerEyeOffsetsM.size());
    pipeline::parallelFor(views.size(), [&](std::size_t i) {
        const double tiltDeg = kDimmerTiltsDeg[i / kDimmerEyeOffsetsM.size()];
        const double offsetM = kDimmerEyeOffsetsM[i % kDimmerEyeOffsetsM.size()];
        sh::View view;
        view.panel = pipeline::scene::panelPose(config.stand,
                                                pipeline::scene::degreesToRadians(tiltDeg));
        view.eye = config.defaultEyeM + glm::dvec3(offsetM, 0.0, 0.0);
        view.pixelsX = 32;
        view.pixelsY = 20;
        DimmerView& v = views[i];
        v.frame = sh::renderRealtime(ps, pl, view, setup.observer, setup.settings);
        for (int py = 0; py < view.pixelsY; ++py) {
            for (int px = 0; px < view.pixelsX; ++px) {
                v.pixelM.push_back(sh::shadingPoint(view, setup.scene, {}, px, py).p);
            }
        }
        v.normal = view.panel.normal;
        v.eyeM = view.eye;
    });
    return views;
}

} // namespace

// The site's [booth] dimmer = "auto": the largest scale at which, for every lamp, at most 1 % of
// the surface over all its probe views together, and at most 5 % in any one view, is above the
// panel's peak as the display pass meets it (pass 1's Y over the viewing-angle gain at each
// pixel's angle to the eye: the run summary's "above the panel's peak"). Logs the scale and, per
// lamp, that share (mean over the views, worst view) and the display's error at the worst view,
// before and after.
void chooseBoothDimmer(RunConfig& config,
                       const pipeline::render::BoothSceneSetup& setup,
                       const pipeline::display::DisplayModel& displayModel)
{
    auto log = logger("booth");
    const double peakY = displayModel.whiteXyz().y;
    std::vector<std::vector<pipeline::shading::XyzFrame>> demand; // per lamp, per view
    double scale = 1.0;
    for (const auto& light : setup.booth.lights) {
        auto& lamp = demand.emplace_back();
        for (const auto& v : dimmerViews(config, setup, light)) {
            lamp.push_back(panelDemand(v, displayModel, config.viewingCompensation));
            scale = std::min(scale, autoBoothDimmer({lamp.back()}, peakY, 0.95));
        }
        scale = std::min(scale, autoBoothDimmer(lamp, peakY, 0.99));
    }
    config.boothDimmer = scale;
    config.boothDimmerAuto = false;
    config.boothDimmerChosenAuto = true;
    auto inverse = pipeline::display::DisplayInverse::build(displayModel);
    for (std::size_t i = 0; i < demand.size(); ++i) {
        const auto share = [&](double s) {
            double sum = 0.0, worst = 0.0;
            std::size_t at = 0;
            for (std::size_t k = 0; k < demand[i].size(); ++k) {
                const double f = overPeakFraction(demand[i][k], s, peakY);
                sum += f;
                at = f > worst ? k : at;
                worst = std::max(worst, f);
            }
            return std::make_tuple(sum / static_cast<double>(demand[i].size()), worst, at);
        };
        const auto [before, beforeWorst, at] = share(1.0);
        const auto [after, afterWorst, unused] = share(scale);
        std::string effect;
        if (inverse) {
            const DimmerEffect b = boothDimmerEffect(demand[i][at], 1.0, *inverse);
            const DimmerEffect a = boothDimmerEffect(demand[i][at], scale, *inverse);
            effect =
                    fmt::format("; display dE00 mean / p95 / max there {:.2f} / {:.2f} / {:.2f} -> "
                                "{:.2f} / {:.2f} / {:.2f}",
                                b.de00Mean, b.de00P95, b.de00Max, a.de00Mean, a.de00P95, a.de00Max);
        }
        log->info("booth dimmer (auto) {:.4f} for the panel's peak {:.0f} cd/m^2; lamp {}: surface "
                  "above the panel's peak{} over {} probe views: mean {:.1f}% -> {:.1f}%, worst "
                  "view {:.1f}% -> {:.1f}%{}",
                  scale, peakY, setup.booth.lights[i].name,
                  config.viewingCompensation ? " (viewing gain included)" : "", demand[i].size(),
                  100.0 * before, 100.0 * after, 100.0 * beforeWorst, 100.0 * afterWorst, effect);
    }
}

} // namespace replica::platform
