// Scene state to booth pass: light selection and caching, view from eye and tilt.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/spectral/light_classifier.h>

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
    for (const auto& lamp : setup.lamps) {
        if (setup.booth.find(lamp) == nullptr) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("render: lamp '{}' has no light in the booth model "
                                         "(it has {})",
                                         lamp, setup.booth.names()));
        }
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
    for (const auto& lamp : s.lamps) {
        std::size_t index = 0;
        const auto it = s.perLamp.find(lamp);
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
    }
    if (v != active_) {
        // Each pass holds its own light and cache: they must follow the variant drawn.
        var.pass->setSurroundIlluminance(pass_->surroundIlluminance());
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
    }
}

void BoothScenePass::setSurroundIlluminance(bool on)
{
    for (auto& v : variants_) {
        v.pass->setSurroundIlluminance(on);
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
                       flat ? 0 : s.horizonDirections, grids, setup_.basis.name,
                       setup_.adaptive ? ", re-encoded for each new light" : "");
}

Expected<void> BoothScenePass::selectLight(const scene::SceneState& state, bool& changed)
{
    changed = false;
    const int lamp = state.lampIndex;
    if (lamp >= 0 && static_cast<std::size_t>(lamp) < setup_.lamps.size()) {
        const booth::BoothLight* l =
                setup_.booth.find(setup_.lamps[static_cast<std::size_t>(lamp)]);
        const int index = static_cast<int>(l - setup_.booth.lights.data());
        if (index == lightIndex_) {
            return {};
        }
        if (auto ok = encodeFor(l->spd, true); !ok) {
            return ok;
        }
        if (auto ok = useVariant(lampVariant_[static_cast<std::size_t>(lamp)]); !ok) {
            return ok;
        }
        light_ = shading::prepareLight(*l, setup_.observer, pass_->settings().lights, setup_.basis);
        lightIndex_ = index;
        changed = true;
    } else {
        // Direct-sensor mode: rebuilt only when the sensed spectrum or luminance changes.
        if (lightIndex_ == -1 && state.illuminant.v == directSpd_.v &&
            state.emitterLuminanceCdM2 == directLuminance_) {
            return {};
        }
        if (auto ok = encodeFor(state.illuminant, false); !ok) {
            return ok;
        }
        if (auto ok = useVariant(0); !ok) {
            return ok;
        }
        direct_ = uniformEmitter(setup_.booth.lights.front(),
                                 state.emitterLuminanceCdM2 * setup_.luminanceScale,
                                 state.illuminant);
        light_ = shading::prepareLight(direct_, setup_.observer, pass_->settings().lights,
                                       setup_.basis);
        directSpd_ = state.illuminant;
        directLuminance_ = state.emitterLuminanceCdM2;
        lightIndex_ = -1;
        changed = true;
    }
    return pass_->setLight(light_);
}

Expected<void> BoothScenePass::encodeFor(const colour::Spectrum& spd, bool lampChange)
{
    if (!setup_.adaptive) {
        return {};
    }
    if (encoded_ && (lampChange ? spd.v == encodedFor_.v
                                : spectral::spectralShapeDistance(spd, encodedFor_) <=
                                          setup_.reencodeDistance)) {
        return {};
    }
    auto basis = setup_.adaptive->basisFor(spd);
    if (!basis) {
        return {}; // no luminance or a non-finite band: keep rendering with the encoding we have
    }
    setup_.basis = std::move(*basis);
    // By linearity a texel's coefficients follow from its palette entries'
    // (SurfaceScene::channels).
    for (std::size_t i = 0; i < setup_.scene.palette.size(); ++i) {
        prepared_->paletteCoeffs[i] =
                colour::projectReflectance(setup_.basis, setup_.scene.palette[i]);
    }
    encodedFor_ = spd;
    encoded_ = true;
    ++encodings_;
    variants_[active_].encodings = encodings_;
    return pass_->setChannels(*prepared_);
}

Expected<void> BoothScenePass::draw(const scene::SceneState& state, int width, int height)
{
    bool lightChanged = false;
    if (auto ok = selectLight(state, lightChanged); !ok) {
        return ok;
    }
    // The cached diffuse term's tilt: the mean of the last kTiltWindow sensed tilts, taken when
    // the light changes (the cache is recomputed anyway) or when that mean has moved more than
    // kTiltHoldRad from the held tilt. Non-finite tilts are left out.
    if (std::isfinite(state.tiltRad)) {
        tiltWindow_[tiltNext_] = state.tiltRad;
        tiltNext_ = (tiltNext_ + 1) % tiltWindow_.size();
        tiltCount_ = std::min(tiltCount_ + 1, tiltWindow_.size());
    }
    if (tiltCount_ > 0) {
        double sum = 0.0;
        for (std::size_t i = 0; i < tiltCount_; ++i) {
            sum += tiltWindow_[i];
        }
        const double mean = sum / static_cast<double>(tiltCount_);
        if (lightChanged || !heldValid_ || std::abs(mean - heldTiltRad_) > kTiltHoldRad) {
            heldTiltRad_ = mean;
            heldValid_ = true;
        }
    }
    const auto pose = [&](double tiltRad) { return scene::panelPose(setup_.stand, tiltRad); };
    const shading::PanelPose held = pose(heldTiltRad_);
    shading::View view;
    // The specular term follows the sensed tilt (a highlight moves twice as fast as the panel);
    // a non-finite one falls back to the held tilt.
    view.panel = std::isfinite(state.tiltRad) ? pose(state.tiltRad) : held;
    view.eye = state.eyeBoothM;
    view.pixelsX = width;
    view.pixelsY = height;
    return pass_->draw(view, width, height, layoutOnPanel(setup_.scene, setup_.stand), &held);
}

PixelRect BoothScenePass::surfaceRect(int width, int height) const
{
    return render::surfaceRect(layoutOnPanel(setup_.scene, setup_.stand), width, height);
}

} // namespace replica::pipeline::render
