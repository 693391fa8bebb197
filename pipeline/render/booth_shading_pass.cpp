// The booth shading pass: which parts it is made of for its settings, and when each runs. The
// parts are booth_programs, booth_inputs (scene and light uploaded), booth_diffuse_cache,
// booth_specular and booth_compose; the target read back by tests and tools is xyz_target's.
#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <glm/common.hpp>

#include <pipeline/render/booth_compose.h>
#include <pipeline/render/booth_shaders.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/render/booth_upload.h>
#include <pipeline/render/gl_program.h>

namespace replica::pipeline::render {
using namespace booth_upload;

namespace {

// glsl/booth_main.glsl eq. (1) on a flat surface: one LIGHT_AT per light up to
// kBoothUnrolledLights, a loop for any beyond. Not on relief: there each light's horizon test
// is large, and 32 copies of it took LLVM seconds to compile (a test's pass 2 -> 16 s) for no
// measurable gain in the frame. Nor with the diffuse grid: eq. (1) then runs only at the
// grid's few hundred nodes (mode 3), where 64 copies of the area light's contour integral
// bought nothing in the frame and cost llvmpipe 4-5 s of JIT before the flat scenes' first
// frame (docs/performance.md, "Start-up"); the frames are bit for bit the same.
// The specular samples likewise, SPEC_AT(k) up to kBoothUnrolledSpecSamples: llvmpipe kept
// the loop and read each sample's half vector as a gather per pixel. Written out, the
// painting's frame took 12 % fewer instructions (callgrind, docs/performance.md). Not with
// the specular grid, where the samples run at the grid's nodes only (mode 2).
// A pass shared by lamps of several counts writes out the fewest (BoothUnroll).
// 'relief' and config's grids are the pass's own decisions (init).
void writeOut(booth_upload::BoothShaderConfig& config,
              bool relief,
              int lights,
              int samples,
              BoothUnroll unroll)
{
    const bool lightsPerPixel = !relief && !config.diffuseGrid;
    const bool samplesPerPixel = config.specular && !config.specularGrid;
    const int l = unroll.lights >= 0 ? std::min(unroll.lights, lights) : lights;
    const int k = unroll.specularSamples >= 0 ? std::min(unroll.specularSamples, samples) : samples;
    config.unrolledLights = lightsPerPixel ? std::clamp(l, 0, kBoothUnrolledLights) : 0;
    config.unrolledSpecularSamples =
            samplesPerPixel ? std::clamp(k, 0, kBoothUnrolledSpecSamples) : 0;
}

} // namespace

Expected<std::unique_ptr<BoothShadingPass>>
BoothShadingPass::create(const shading::PreparedScene& scene,
                         const shading::RenderSettings& settings,
                         const colour::Observer& obs,
                         BoothUnroll unroll)
{
    if (scene.scene == nullptr || scene.scene->width <= 0 || scene.scene->height <= 0) {
        return makeError(ErrorCode::InvalidArgument, "render: the booth pass needs a loaded scene");
    }
    std::unique_ptr<BoothShadingPass> pass(new BoothShadingPass());
    pass->settings_ = settings;
    pass->observer_ = &obs;
    if (auto ok = pass->init(scene, unroll); !ok) {
        return tl::unexpected(ok.error());
    }
    return pass;
}

Expected<void> BoothShadingPass::init(const shading::PreparedScene& ps, BoothUnroll unroll)
{
    scene_ = &ps;
    const surface::SurfaceScene& s = *ps.scene;
    const bool relief = settings_.reliefPass && !ps.normals.empty();
    const int horizonDirs = relief && settings_.horizonDirections > 0 ? ps.horizon.directions : 0;
    if (horizonDirs > kBoothMaxHorizonDirections) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} horizon directions; the GL pass holds at most {}",
                                     horizonDirs, kBoothMaxHorizonDirections));
    }
    if (!exactLevelTwiceBias(settings_)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: the GL pass reads the nearest specular mip level at "
                                     "a bias of whole half levels (within {}); {} with a bias of "
                                     "{} is the CPU model's alone",
                                     shading::kMaxSpecularLodBias,
                                     settings_.specularNearestLevel ? "the nearest level"
                                                                    : "trilinear levels",
                                     settings_.specularLodBias));
    }
    // The luminance chain is filtered by the sampler where the GL can filter float textures and
    // clamp to a border (GLES 3.2 has both's core equivalents only for the border); otherwise the
    // shader filters by hand with texelFetch, the same rule.
    hwFilter_ = hasExtension("GL_OES_texture_float_linear") &&
                (hasExtension("GL_EXT_texture_border_clamp") ||
                 hasExtension("GL_OES_texture_border_clamp"));
    // Which passes run is fixed for the pass's life: compiled into each program, so that none
    // carries code it never runs (llvmpipe executes both sides of a branch under a mask).
    specular_ = settings_.specularPass && s.glossy() && settings_.specularSamples > 0;
    const shading::GridNodes specularNodes =
            specular_ ? shading::gridNodes(s, settings_.specularGrid) : shading::GridNodes{};
    const bool facetCache = relief && specular_ && specularNodes.x == 0;
    const shading::GridNodes diffuseNodes = shading::gridNodes(s, settings_.diffuseGrid);
    const int samples = specular_ ? settings_.specularSamples : 0;
    if (samples > kBoothMaxSpecularSamples) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} specular samples; the GL pass takes at most {}",
                                     samples, kBoothMaxSpecularSamples));
    }
    // Horizon sines a layer of the horizon texture (horizonTexture, half floats) and layers.
    const int perLayer = 8;
    const int layers = std::max((horizonDirs + perLayer - 1) / perLayer, 1);
    BoothShaderConfig config;
    config.relief = relief;
    config.specularGrid = specularNodes.x > 0;
    config.diffuseGrid = diffuseNodes.x > 0;
    config.hardwareFilter = hwFilter_;
    config.horizonDirections = horizonDirs;
    config.horizonSlots = perLayer * layers;
    config.specular = samples > 0;
    config.wardModel = s.model;
    config.facetCache = facetCache;
    writeOut(config, relief, settings_.lights, samples, unroll);
    unrolledSamples_ = config.unrolledSpecularSamples;
    if (auto ok = programs_.compile(config, settings_, diffuseNodes.x > 0 ? 4 : 3); !ok) {
        return ok;
    }
    vao_ = GlVertexArray::make();
    inputs_.uploadScene(ps, relief, horizonDirs, programs_);
    // The grids' targets: the specular one shaded every frame (mode 2), the diffuse one drawn
    // whenever the cache is (mode 3).
    if (auto ok = specularTerm_.init(s, samples, specularNodes, programs_); !ok) {
        return ok;
    }
    if (auto ok = cache_.init(settings_.cacheSlices, settings_.tiltNodesRad > 0.0, facetCache,
                              diffuseNodes, relief, programs_);
        !ok) {
        return ok;
    }

    programs_.uniformAll(glProgramUniform2i, "uTexels", s.width, s.height);
    programs_.uniformAll(glProgramUniform2f, "uSizeM", static_cast<float>(s.widthM),
                         static_cast<float>(s.heightM));
    programs_.uniformAll(glProgramUniform1f, "uSoftness",
                         static_cast<float>(settings_.horizonSoftness));
    programs_.uniformAll(glProgramUniform1f, "uLodScale",
                         std::ldexp(1.0f, *exactLevelTwiceBias(settings_)));
    programs_.uniformAll(glProgramUniform1i, "uDiffuse", settings_.diffusePass ? 1 : 0);
    programs_.uniformAll(
            glProgramUniform1f, "uFlareRho",
            static_cast<float>(settings_.subtractFlare ? shading::kScreenFlareRho : 0.0));
    return glCheck("uploading the scene");
}

BoothShadingPass::~BoothShadingPass() = default;

Expected<void> BoothShadingPass::setCounts(int lights, int specularSamples)
{
    if (lights < 1 || lights > kBoothMaxLights) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} lights; the GL pass holds 1 to {}", lights,
                                     kBoothMaxLights));
    }
    if (specular_ && (specularSamples < std::max(unrolledSamples_, 1) ||
                      specularSamples > kBoothMaxSpecularSamples)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} specular samples; this pass writes out {} and "
                                     "takes {} to {}",
                                     specularSamples, unrolledSamples_,
                                     std::max(unrolledSamples_, 1), kBoothMaxSpecularSamples));
    }
    settings_.lights = lights;
    if (specular_ && specularSamples != specularTerm_.samples()) {
        specularTerm_.setSamples(*scene_->scene, specularSamples, programs_);
        settings_.specularSamples = specularSamples;
        return glCheck("setting the specular samples");
    }
    return {};
}

Expected<void> BoothShadingPass::setChannels(const shading::PreparedScene& ps)
{
    if (ps.scene == nullptr || scene_ == nullptr || ps.scene->width != scene_->scene->width ||
        ps.scene->height != scene_->scene->height ||
        ps.paletteCoeffs.size() != ps.scene->palette.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         "render: new channel coefficients must be for a scene of the same size, "
                         "with one set per palette entry");
    }
    scene_ = &ps;
    inputs_.replaceChannels(ps);
    cache_.invalidate(); // the cached diffuse term was shaded from the old coefficients
    return glCheck("replacing the channel coefficients");
}

Expected<void> BoothShadingPass::setLight(const shading::PreparedLight& pl)
{
    if (pl.light == nullptr || pl.mips.levels.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "render: the booth pass needs a prepared light");
    }
    light_ = &pl;
    programs_.setWalls(pl.walls, scene_->scene);
    cache_.invalidate();
    return inputs_.uploadLight(pl, *scene_->scene, *observer_, hwFilter_, programs_);
}

Expected<void> BoothShadingPass::draw(const shading::View& view,
                                      int width,
                                      int height,
                                      const SurfaceLayout& layout,
                                      const CacheWant* cache)
{
    if (light_ == nullptr) {
        return makeError(ErrorCode::InvalidArgument, "render: booth pass drawn before setLight");
    }
    if (width <= 0 || height <= 0) {
        return makeError(ErrorCode::InvalidArgument, "render: booth pass drawn into an empty "
                                                     "viewport");
    }
    GLint target = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target);
    if (auto ok = cache_.ensureTarget(width, height); !ok) {
        glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target));
        return ok;
    }
    glViewport(0, 0, width, height);
    glBindVertexArray(vao_.get());
    programs_.uniformAll(glProgramUniform2f, "uViewport", static_cast<float>(width),
                         static_cast<float>(height));
    programs_.uniformAll(glProgramUniform2f, "uSurfOffset", static_cast<float>(layout.offset.x),
                         static_cast<float>(layout.offset.y));
    programs_.uniformAll(glProgramUniform2f, "uSurfScale", static_cast<float>(layout.scale.x),
                         static_cast<float>(layout.scale.y));
    // The same rectangle in window pixels (u = 0 to 1 left to right, v = 0 to 1 top to bottom):
    // the default layout's are whole numbers, (0, height, width, height).
    const glm::dvec2 sx = glm::max(layout.scale, glm::dvec2(1e-9));
    programs_.uniformAll(glProgramUniform4f, "uSurfPixels",
                         static_cast<float>(-layout.offset.x * width / sx.x),
                         static_cast<float>(height * (1.0 + layout.offset.y / sx.y)),
                         static_cast<float>(width / sx.x), static_cast<float>(height / sx.y));
    programs_.set3All("uEye", view.eye);
    inputs_.bind();
    specularTerm_.bind();
    glActiveTexture(GL_TEXTURE0 + kUnitCache);
    glBindTexture(GL_TEXTURE_2D, 0); // not sampled while it is the render target

    // What the surface can light (the whole viewport for a layout that does not scale): what the
    // compose draws, and all the cache holds without the surround's illuminance.
    const PixelRect rect = surfaceRect(layout, width, height);
    cache_.update(programs_,
                  cache != nullptr ? *cache
                                   : CacheWant{view.panel, std::nullopt, std::nullopt, 0.0},
                  layout, rect, width, height);
    specularTerm_.drawGrid(programs_, view.panel, width, height);
    // Without a specular term or flare to add the frame is the cache as it is.
    composeBoothFrame(programs_, cache_, specularTerm_,
                      {static_cast<GLuint>(target), rect, width, height}, view.panel,
                      specular_ || settings_.subtractFlare);
    glActiveTexture(GL_TEXTURE0);
    return glCheck("drawing the booth pass");
}

} // namespace replica::pipeline::render
