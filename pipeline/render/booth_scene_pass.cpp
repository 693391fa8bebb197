// Scene state to booth pass: the state's light, encoding and tilts uploaded where the GPU holds
// others, then drawn.
#include <algorithm>
#include <chrono>
#include <numbers>

#include <GLES3/gl31.h>
#include <fmt/format.h>

#include <pipeline/reference/wall_radiosity.h>
#include <pipeline/render/booth_scene_pass.h>

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
    // A booth with walls lights each lamp's passes with them unless the lamp's plan leaves them
    // out (LampSettings::walls); each lamp's walls solved once here.
    setup.settings.walls = setup.booth.walls.has_value();
    if (setup.booth.walls) {
        reference::WallSolveOptions o;
        o.patchM = kRealtimeWallPatchM;
        for (const auto& lamp : setup.booth.lights) {
            p->walls_.push_back(reference::solveWalls(*setup.booth.walls, lamp, setup.observer, o));
        }
    }
    p->setup_ = std::move(setup);
    const auto& s = p->setup_;
    // Variant 0: the setup's settings (the direct-sensor mode's, and a lamp's without settings of
    // its own). One pass is made now (below); the others at their first use or warm-up
    // (makeVariant): what only a lamp that is not shown yet needs is not done before the first
    // frame.
    p->variants_.push_back(Variant{s.settings, {}, nullptr, nullptr, 0});
    narrow(p->variants_[0], s.settings);
    for (const auto& lamp : s.booth.lights) {
        shading::RenderSettings settings = s.settings;
        if (const auto it = s.perLamp.find(lamp.name); it != s.perLamp.end()) {
            settings.lights = it->second.lights;
            if (s.scene.glossy()) {
                settings.specularSamples = it->second.specularSamples;
            }
            if (!s.scene.flat() && it->second.horizonDirections > 0) {
                settings.horizonDirections = it->second.horizonDirections;
            }
            settings.walls = settings.walls && it->second.walls;
        }
        // Lamps whose programs would be the same share one pass: their counts of lights and
        // specular samples are uniforms the pass takes at the switch (BoothShadingPass::
        // setCounts), written out for the fewest of them where the programs write them out, so
        // the switch between them compiles nothing. What the programs are made of (horizon
        // directions, the walls, a specular term or none) makes a pass of its own.
        const auto same = [&](const Variant& v) {
            return (v.settings.specularSamples > 0) == (settings.specularSamples > 0) &&
                   v.settings.horizonDirections == settings.horizonDirections &&
                   v.settings.walls == settings.walls;
        };
        auto found = std::find_if(p->variants_.begin(), p->variants_.end(), same);
        if (found == p->variants_.end()) {
            p->variants_.push_back(Variant{settings, {}, nullptr, nullptr, 0});
            found = p->variants_.end() - 1;
        }
        narrow(*found, settings);
        p->lampVariant_.push_back(static_cast<std::size_t>(found - p->variants_.begin()));
        p->lampSettings_.push_back(settings);
    }
    // The first lamp's pass made now, or variant 0's; every other at its first use or warm-up.
    const std::size_t first =
            s.firstLamp >= 0 && static_cast<std::size_t>(s.firstLamp) < p->lampVariant_.size()
                    ? p->lampVariant_[static_cast<std::size_t>(s.firstLamp)]
                    : 0;
    if (auto ok = p->makeVariant(first); !ok) {
        return tl::unexpected(ok.error());
    }
    p->active_ = first;
    p->drawn_.assign(p->variants_.size(), false);
    p->basis_ = s.basis;
    p->prepared_ = p->variants_[first].prepared.get();
    p->pass_ = p->variants_[first].pass.get();
    return p;
}

Expected<void> BoothScenePass::makeVariant(std::size_t v)
{
    Variant& var = variants_[v];
    if (var.pass) {
        return {};
    }
    // The scene prepared for the variant's horizon directions, in the setup's basis (encoding 0:
    // useVariant brings its channels to the encoding drawn).
    const int directions = std::max(var.settings.horizonDirections, 1);
    auto prepared = std::make_unique<shading::PreparedScene>(
            setup_.prepared && !setup_.scene.flat() &&
                            setup_.prepared->horizon.directions == directions
                    ? shading::reprojectScene(*setup_.prepared, setup_.scene, setup_.basis)
                    : shading::prepareScene(setup_.scene, directions, 0.01, setup_.basis));
    // Made in the middle of a frame (its first use): the pass's creation binds framebuffers and
    // textures of its own; the frame's target, viewport and texture unit come back.
    GLint drawFb = 0;
    GLint readFb = 0;
    GLint unit = 0;
    GLint viewport[4] = {0, 0, 0, 0};
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFb);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readFb);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &unit);
    glGetIntegerv(GL_VIEWPORT, viewport);
    auto pass = BoothShadingPass::create(*prepared, var.settings, setup_.observer, var.unroll);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(drawFb));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(readFb));
    glActiveTexture(static_cast<GLenum>(unit));
    glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    if (!pass) {
        return tl::unexpected(pass.error());
    }
    if (pass_ != nullptr) {
        (*pass)->setSurroundIlluminance(pass_->surroundIlluminance());
    }
    var.prepared = std::move(prepared);
    var.pass = std::move(*pass);
    var.encodings = 0;
    return {};
}

Expected<void> BoothScenePass::useVariant(std::size_t v)
{
    if (auto ok = makeVariant(v); !ok) {
        return ok;
    }
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
        n += v.pass ? v.pass->cacheRefreshes() : 0;
    }
    return n - warmUpRefreshes_;
}

void BoothScenePass::invalidateCache()
{
    for (auto& v : variants_) {
        if (v.pass) {
            v.pass->invalidateCache();
        }
    }
}

void BoothScenePass::setSurroundIlluminance(bool on)
{
    for (auto& v : variants_) {
        if (v.pass) {
            v.pass->setSurroundIlluminance(on); // one made later takes it from pass_
        }
    }
}

std::string BoothScenePass::description() const
{
    const auto& s = pass_->settings();
    const bool glossy = setup_.scene.glossy();
    const bool flat = setup_.scene.flat();
    const std::string grids =
            (glossy && s.specularGrid > 0 ? fmt::format(", specular grid {} texels", s.specularGrid)
                                          : std::string()) +
            (s.diffuseGrid > 0 ? fmt::format(", diffuse grid {} texels", s.diffuseGrid)
                               : std::string()) +
            (s.cacheSlices > 1 ? fmt::format(", a tilt recomputed over {} frames", s.cacheSlices)
                               : std::string()) +
            (s.tiltNodesRad > 0.0 ? fmt::format(", tilt nodes {:.3g} degrees apart",
                                                s.tiltNodesRad * 180.0 / std::numbers::pi)
                                  : std::string());
    return fmt::format("gles-booth (scene {}, {} median-cut lights, {} specular samples, {} "
                       "horizon directions{}, basis {}{})",
                       setup_.scene.name, s.lights, glossy ? s.specularSamples : 0,
                       flat ? 0 : s.horizonDirections, grids, basis_.name,
                       setup_.adaptive ? ", re-encoded for each new light" : "");
}

Expected<void> BoothScenePass::selectLight(const scene::SceneState& state)
{
    // The light the GPU holds is labelled with its content key (the state stage's, the same key
    // by which it says a light changed) and its encoding.
    const std::uint64_t key = scene::lightKey(state);
    if (heldLight_ == key && state.encoding == encodings_) {
        return {};
    }
    if (auto ok = applyEncoding(state); !ok) {
        return ok;
    }
    const int lamp = state.lampIndex;
    const bool isLamp = lamp >= 0 && static_cast<std::size_t>(lamp) < setup_.booth.lights.size();
    if (auto ok = useVariant(isLamp ? lampVariant_[static_cast<std::size_t>(lamp)] : 0); !ok) {
        return ok;
    }
    const shading::RenderSettings& counts =
            isLamp ? lampSettings_[static_cast<std::size_t>(lamp)] : setup_.settings;
    if (auto ok = pass_->setCounts(counts.lights, counts.specularSamples); !ok) {
        return ok;
    }
    if (isLamp) {
        light_ = shading::prepareLight(setup_.booth.lights[static_cast<std::size_t>(lamp)],
                                       setup_.observer, pass_->settings().lights, basis_);
        light_.walls = walls_.empty() ? nullptr : &walls_[static_cast<std::size_t>(lamp)];
    } else {
        // Direct-sensor mode: a uniform emitter with the sensed spectrum.
        direct_ = uniformEmitter(setup_.booth.lights.front(),
                                 state.emitterLuminanceCdM2 * setup_.luminanceScale,
                                 state.illuminant);
        light_ = shading::prepareLight(direct_, setup_.observer, pass_->settings().lights, basis_);
    }
    heldLight_ = key;
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
    return pass_->setChannels(*prepared_);
}

Expected<void> BoothScenePass::draw(const scene::SceneState& state, int width, int height)
{
    const auto start = std::chrono::steady_clock::now();
    if (auto ok = selectLight(state); !ok) {
        return ok;
    }
    // The tilts are the state stage's (a finite specular tilt, the diffuse term and its band);
    // the stand turns each into the panel's pose.
    const auto pose = [&](double tiltRad) { return scene::panelPose(setup_.stand, tiltRad); };
    shading::View view;
    view.panel = pose(state.tiltRad);
    view.eye = state.eyeBoothM;
    view.pixelsX = width;
    view.pixelsY = height;
    CacheWant want{view.panel, std::nullopt, std::nullopt, 0.0};
    if (state.diffuse) {
        want.shown = pose(state.diffuse->shownRad);
        if (const auto& b = state.diffuse->band) {
            want.band = CacheBand{pose(b->towardRad), b->band, b->bands};
        }
        if (state.diffuse->mixRad) {
            want.mixWith = pose(*state.diffuse->mixRad);
            want.mix = state.diffuse->mix;
        }
    }
    const auto layout = layoutOnPanel(setup_.scene, setup_.stand);
    if (drawn_[active_]) {
        return pass_->draw(view, width, height, layout, &want);
    }
    // The pass's first draw in this context: its shaders compile now (llvmpipe: at the draw),
    // and it was made in selectLight unless it was warmed up.
    auto ok = pass_->draw(view, width, height, layout, &want);
    drawn_[active_] = true;
    ++firstUseDraws_;
    lastFirstUseMs_ =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
    return ok;
}

void BoothScenePass::narrow(Variant& v, const shading::RenderSettings& member)
{
    const auto fewest = [](int held, int count) {
        return held < 0 ? count : std::min(held, count);
    };
    v.unroll.lights = fewest(v.unroll.lights, member.lights);
    v.unroll.specularSamples = fewest(v.unroll.specularSamples, member.specularSamples);
}

std::vector<std::size_t> BoothScenePass::variantsNotDrawn() const
{
    // The lamps' passes first, in lamp order, then any no lamp draws (variant 0 when every lamp
    // has a setting of its own: only the direct-sensor mode draws it).
    std::vector<std::size_t> v;
    const auto add = [&](std::size_t i) {
        if (!drawn_[i] && std::find(v.begin(), v.end(), i) == v.end()) {
            v.push_back(i);
        }
    };
    for (const std::size_t i : lampVariant_) {
        add(i);
    }
    for (std::size_t i = 0; i < drawn_.size(); ++i) {
        add(i);
    }
    return v;
}

PixelRect BoothScenePass::surfaceRect(int width, int height) const
{
    return render::surfaceRect(layoutOnPanel(setup_.scene, setup_.stand), width, height);
}

} // namespace replica::pipeline::render
