// Scene state to booth pass: the state's light, encoding and tilts uploaded where the GPU holds
// others, then drawn.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/scene/diffuse_schedule.h>

namespace replica::pipeline::render {

booth::BoothLight
uniformEmitter(const booth::BoothLight& like, double luminanceCdM2, const colour::Spectrum& spd)
{
    booth::BoothLight l;
    l.name = "sensed";
    l.centre = like.centre;
    l.edgeU = like.edgeU;
    l.edgeV = like.edgeV;
    // A coarse image is exact for a uniform emitter: median cut splits it into equal cells.
    l.luminance = booth::LuminanceImage::filled(32, 16, std::max(luminanceCdM2, 0.0));
    l.spd = spd;
    return l;
}

Expected<std::unique_ptr<BoothScenePass>> BoothScenePass::create(BoothSceneSetup setup)
{
    if (setup.booth.lights.empty()) {
        return makeError(ErrorCode::InvalidArgument, "render: the booth model has no lights");
    }
    std::unique_ptr<BoothScenePass> p(new BoothScenePass());
    p->setup_ = std::move(setup);
    const auto& s = p->setup_;
    const auto makeVariant = [&](const shading::RenderSettings& settings) -> Expected<void> {
        Variant v;
        v.settings = settings;
        v.prepared = std::make_unique<shading::PreparedScene>(shading::prepareScene(
                s.scene, std::max(settings.horizonDirections, 1), 0.01, s.basis));
        auto pass = BoothShadingPass::create(*v.prepared, settings, p->setup_.observer);
        if (!pass) {
            return tl::unexpected(pass.error());
        }
        v.pass = std::move(*pass);
        p->variants_.push_back(std::move(v));
        return {};
    };
    if (auto ok = makeVariant(s.settings); !ok) {
        return tl::unexpected(ok.error());
    }
    for (const auto& lamp : s.booth.lights) {
        std::size_t index = 0;
        const auto it = s.perLamp.find(lamp.name);
        if (it != s.perLamp.end()) {
            shading::RenderSettings settings = s.settings;
            settings.lights = it->second.lights;
            if (s.scene.glossy()) {
                settings.specularSamples = it->second.specularSamples;
            }
            if (!s.scene.flat() && it->second.horizonDirections > 0) {
                settings.horizonDirections = it->second.horizonDirections;
            }
            const auto same = [&](const Variant& v) {
                return v.settings.lights == settings.lights &&
                       v.settings.specularSamples == settings.specularSamples &&
                       v.settings.horizonDirections == settings.horizonDirections;
            };
            const auto found = std::find_if(p->variants_.begin(), p->variants_.end(), same);
            if (found == p->variants_.end()) {
                if (auto ok = makeVariant(settings); !ok) {
                    return tl::unexpected(ok.error());
                }
                index = p->variants_.size() - 1;
            } else {
                index = static_cast<std::size_t>(found - p->variants_.begin());
            }
        }
        p->lampVariant_.push_back(index);
    }
    p->active_ = 0;
    p->basis_ = s.basis;
    p->prepared_ = p->variants_[0].prepared.get();
    p->pass_ = p->variants_[0].pass.get();
    return p;
}

Expected<void> BoothScenePass::useVariant(std::size_t v)
{
    Variant& var = variants_[v];
    if (var.encodings != encodings_) {
        var.prepared->paletteCoeffs = prepared_->paletteCoeffs;
        if (auto ok = var.pass->setChannels(*var.prepared); !ok) {
            return ok;
        }
        var.encodings = encodings_;
        var.holds.valid = false;
    }
    if (v != active_) {
        // Each pass holds its own light and cache: they must follow the variant drawn.
        var.pass->setSurroundIlluminance(pass_->surroundIlluminance());
        var.holds.valid = false;
        active_ = v;
        prepared_ = var.prepared.get();
        pass_ = var.pass.get();
    }
    return {};
}

long BoothScenePass::cacheRefreshes() const
{
    long n = 0;
    for (const auto& v : variants_) {
        n += v.pass->cacheRefreshes();
    }
    return n - warmUpRefreshes_;
}

void BoothScenePass::invalidateCache()
{
    for (auto& v : variants_) {
        v.pass->invalidateCache();
        v.holds.valid = false;
    }
}

void BoothScenePass::setSurroundIlluminance(bool on)
{
    for (auto& v : variants_) {
        v.pass->setSurroundIlluminance(on);
        v.holds.valid = false;
    }
}

std::string BoothScenePass::description() const
{
    const auto& s = variants_[active_].settings;
    const bool glossy = setup_.scene.glossy();
    const bool flat = setup_.scene.flat();
    const std::string grids =
            (glossy && s.specularGrid > 0 ? fmt::format(", specular grid {} texels", s.specularGrid)
                                          : std::string()) +
            (flat && s.diffuseGrid > 0 ? fmt::format(", diffuse grid {} texels", s.diffuseGrid)
                                       : std::string()) +
            (s.cacheSlices > 1 ? fmt::format(", a tilt recomputed over {} frames", s.cacheSlices)
                               : std::string());
    return fmt::format("gles-booth (scene {}, {} median-cut lights, {} specular samples, {} "
                       "horizon directions{}, basis {}{})",
                       setup_.scene.name, s.lights, glossy ? s.specularSamples : 0,
                       flat ? 0 : s.horizonDirections, grids, basis_.name,
                       setup_.adaptive ? ", re-encoded for each new light" : "");
}

std::vector<colour::Spectrum> BoothScenePass::lampSpectra() const
{
    std::vector<colour::Spectrum> out;
    for (const auto& lamp : setup_.booth.lights) {
        out.push_back(lamp.spd);
    }
    return out;
}

Expected<void> BoothScenePass::selectLight(const scene::SceneState& state)
{
    const int lamp = state.lampIndex;
    const bool isLamp = lamp >= 0 && static_cast<std::size_t>(lamp) < setup_.booth.lights.size();
    const booth::BoothLight* l =
            isLamp ? &setup_.booth.lights[static_cast<std::size_t>(lamp)] : nullptr;
    const int index = isLamp ? lamp : -1;
    const bool onGpu = index == lightIndex_ && state.encoding == encodings_ &&
                       (isLamp || (state.illuminant.v == directSpd_.v &&
                                   state.emitterLuminanceCdM2 == directLuminance_));
    if (onGpu && !state.lightChanged) {
        return {};
    }
    if (auto ok = applyEncoding(state); !ok) {
        return ok;
    }
    if (auto ok = useVariant(isLamp ? lampVariant_[static_cast<std::size_t>(lamp)] : 0); !ok) {
        return ok;
    }
    if (isLamp) {
        light_ = shading::prepareLight(*l, setup_.observer, pass_->settings().lights, basis_);
    } else {
        // Direct-sensor mode: a uniform emitter with the sensed spectrum.
        direct_ = uniformEmitter(setup_.booth.lights.front(),
                                 state.emitterLuminanceCdM2 * setup_.luminanceScale,
                                 state.illuminant);
        light_ = shading::prepareLight(direct_, setup_.observer, pass_->settings().lights, basis_);
        directSpd_ = state.illuminant;
        directLuminance_ = state.emitterLuminanceCdM2;
    }
    lightIndex_ = index;
    variants_[active_].holds.valid = false; // a new light draws the cache whole
    return pass_->setLight(light_);
}

Expected<void> BoothScenePass::applyEncoding(const scene::SceneState& state)
{
    if (state.encoding == encodings_) {
        return {};
    }
    if (state.encoding > 0 && !state.basis) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("render: encoding {} comes without its basis", state.encoding));
    }
    basis_ = state.encoding > 0 ? *state.basis : setup_.basis;
    // By linearity a texel's coefficients follow from its palette entries'
    // (SurfaceScene::channels).
    for (std::size_t i = 0; i < setup_.scene.palette.size(); ++i) {
        prepared_->paletteCoeffs[i] = colour::projectReflectance(basis_, setup_.scene.palette[i]);
    }
    encodings_ = state.encoding;
    variants_[active_].encodings = encodings_;
    variants_[active_].holds.valid = false;
    return pass_->setChannels(*prepared_);
}

Expected<void> BoothScenePass::drawCached(const scene::SceneState& state,
                                          const shading::View& view,
                                          int width,
                                          int height)
{
    Variant& var = variants_[active_];
    const int k = std::max(var.settings.cacheSlices, 1);
    const auto pose = [&](double tiltRad) { return scene::panelPose(setup_.stand, tiltRad); };
    const SurfaceLayout layout = layoutOnPanel(setup_.scene, setup_.stand);
    const double sensed = std::isfinite(state.tiltRad) ? state.tiltRad : state.heldTiltRad;
    const scene::DiffuseTilt want =
            state.diffuse ? *state.diffuse : scene::DiffuseTilt{sensed, std::nullopt, 0};
    // The one draw that takes the cache from what it holds to what the state says, where the
    // state is the schedule's next frame after it (the same diffuse term, the next band of a
    // refresh, or its last band): the cache at diffuseTarget(want) draws that band.
    const bool oneDraw = var.holds.valid && scene::diffuseFollows(var.holds.diffuse, want, k);
    var.holds = {true, want};
    if (oneDraw) {
        const scene::PanelPose p = pose(scene::diffuseTarget(want));
        return pass_->draw(view, width, height, layout, &p);
    }
    // Otherwise (a fresh pass, a new light, frame N drawn alone): the shown diffuse term whole,
    // then a refresh's bands so far; the last draw is the frame.
    pass_->invalidateCache();
    const scene::PanelPose shown = pose(want.shownRad);
    if (auto ok = pass_->draw(view, width, height, layout, &shown); !ok || !want.refreshRad) {
        return ok;
    }
    const scene::PanelPose target = pose(*want.refreshRad);
    for (int band = 0; band < want.refreshBands; ++band) {
        if (auto ok = pass_->draw(view, width, height, layout, &target); !ok) {
            return ok;
        }
    }
    return {};
}

Expected<void> BoothScenePass::draw(const scene::SceneState& state, int width, int height)
{
    if (auto ok = selectLight(state); !ok) {
        return ok;
    }
    shading::View view;
    // The specular term follows the sensed tilt (a highlight moves twice as fast as the panel);
    // a non-finite one falls back to the held tilt.
    view.panel = scene::panelPose(setup_.stand,
                                  std::isfinite(state.tiltRad) ? state.tiltRad : state.heldTiltRad);
    view.eye = state.eyeBoothM;
    view.pixelsX = width;
    view.pixelsY = height;
    return drawCached(state, view, width, height);
}

PixelRect BoothScenePass::surfaceRect(int width, int height) const
{
    return render::surfaceRect(layoutOnPanel(setup_.scene, setup_.stand), width, height);
}

} // namespace replica::pipeline::render
