// Host side of the booth shading pass: the programs, the scene and light uploaded, the cache of
// the eye-independent part, the draw. The upload helpers are booth_upload.cpp's, the target
// read back by tests and tools xyz_target.cpp's.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/gtc/packing.hpp>

#include <pipeline/brdf/ward.h>
#include <pipeline/render/booth_shaders.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/render/booth_upload.h>
#include <pipeline/render/gl_program.h>

namespace replica::pipeline::render {
using namespace booth_upload;
namespace {

enum TextureUnit : GLint {
    kUnitCoeffA = 0,
    kUnitCoeffB,
    kUnitNormals,
    kUnitHorizon,
    kUnitLum,
    kUnitCache,
    kUnitSpecGrid,
    kUnitFacet,
    kUnitDiffGrid
};

} // namespace

SurfaceLayout layoutOnPanel(const surface::SurfaceScene& scene, const scene::StandModel& stand)
{
    SurfaceLayout l;
    if (scene.widthM > 0.0 && scene.heightM > 0.0) {
        l.scale = {stand.panelWidthM / scene.widthM, stand.panelHeightM / scene.heightM};
        l.offset = {0.5 - 0.5 * l.scale.x, 0.5 - 0.5 * l.scale.y};
    }
    return l;
}

PixelRect surfaceRect(const SurfaceLayout& layout, int width, int height)
{
    if (!(layout.scale.x > 0.0) || !(layout.scale.y > 0.0)) {
        return {0, 0, width, height};
    }
    const auto span = [](double offset, double scale, int n) {
        const double a = (0.0 - offset) / scale * n;
        const double b = (1.0 - offset) / scale * n;
        const int lo = std::clamp(static_cast<int>(std::floor(std::min(a, b))) - 1, 0, n);
        const int hi = std::clamp(static_cast<int>(std::ceil(std::max(a, b))) + 1, 0, n);
        return std::pair<int, int>(lo, hi);
    };
    const auto [x0, x1] = span(layout.offset.x, layout.scale.x, width);
    const auto [r0, r1] = span(layout.offset.y, layout.scale.y, height); // rows down
    return {x0, height - r1, x1 - x0, r1 - r0};
}

Expected<std::unique_ptr<BoothShadingPass>>
BoothShadingPass::create(const shading::PreparedScene& scene,
                         const shading::RenderSettings& settings,
                         const colour::Observer& obs)
{
    if (scene.scene == nullptr || scene.scene->width <= 0 || scene.scene->height <= 0) {
        return makeError(ErrorCode::InvalidArgument, "render: the booth pass needs a loaded scene");
    }
    std::unique_ptr<BoothShadingPass> pass(new BoothShadingPass());
    pass->settings_ = settings;
    pass->observer_ = &obs;
    if (auto ok = pass->init(scene); !ok) {
        return tl::unexpected(ok.error());
    }
    return pass;
}

Expected<void> BoothShadingPass::init(const shading::PreparedScene& ps)
{
    scene_ = &ps;
    const surface::SurfaceScene& s = *ps.scene;
    relief_ = settings_.reliefPass && !ps.normals.empty();
    horizonDirs_ = relief_ && settings_.horizonDirections > 0 ? ps.horizon.directions : 0;
    if (horizonDirs_ > kBoothMaxHorizonDirections) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} horizon directions; the GL pass holds at most {}",
                                     horizonDirs_, kBoothMaxHorizonDirections));
    }
    // The luminance chain is filtered by the sampler where the GL can filter float textures and
    // clamp to a border (GLES 3.2 has both's core equivalents only for the border); otherwise the
    // shader filters by hand with texelFetch, the same rule.
    hwFilter_ = settings_.hardwareFilter && hasExtension("GL_OES_texture_float_linear") &&
                (hasExtension("GL_EXT_texture_border_clamp") ||
                 hasExtension("GL_OES_texture_border_clamp"));
    // Which passes run is fixed for the pass's life: compiled into each program, so that none
    // carries code it never runs (llvmpipe executes both sides of a branch under a mask).
    specular_ = settings_.specularPass && s.glossy() && settings_.specularSamples > 0;
    gridNodes_ = specular_ ? shading::gridNodes(s, settings_.specularGrid) : shading::GridNodes{};
    facetCache_ = relief_ && specular_ && gridNodes_.x == 0;
    diffuseNodes_ = relief_ ? shading::GridNodes{} : shading::gridNodes(s, settings_.diffuseGrid);
    // The specular samples' half vectors depend only on alpha and N: once here, in double.
    const int samples = specular_ ? settings_.specularSamples : 0;
    if (samples > kBoothMaxSpecularSamples) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} specular samples; the GL pass takes at most {}",
                                     samples, kBoothMaxSpecularSamples));
    }
    // Horizon sines a layer of the horizon texture (horizonTexture) and layers.
    const int perLayer = settings_.horizonHalf ? 8 : 4;
    const int layers = std::max((horizonDirs_ + perLayer - 1) / perLayer, 1);
    // glsl/booth_main.glsl eq. (1) on a flat surface: one LIGHT_AT per light up to
    // kBoothUnrolledLights, a loop for any beyond. Not on relief: there each light's horizon test
    // is large, and 32 copies of it took LLVM seconds to compile (a test's pass 2 -> 16 s) for no
    // measurable gain in the frame.
    const int unrolledLights = relief_ ? 0 : std::clamp(settings_.lights, 0, kBoothUnrolledLights);
    // The specular samples likewise, SPEC_AT(k) up to kBoothUnrolledSpecSamples: llvmpipe kept
    // the loop and read each sample's half vector as a gather per pixel. Written out, the
    // painting's frame took 12 % fewer instructions (callgrind, docs/performance.md).
    const int unrolledSpec = std::clamp(samples, 0, kBoothUnrolledSpecSamples);
    const int modes = diffuseNodes_.x > 0 ? 4 : 3;
    for (int mode = 0; mode < modes; ++mode) {
        BoothShaderConfig config;
        config.mode = mode;
        config.relief = relief_;
        config.specularGrid = gridNodes_.x > 0;
        config.diffuseGrid = diffuseNodes_.x > 0;
        config.hardwareFilter = hwFilter_;
        config.horizonDirections = horizonDirs_;
        config.horizonSlots = perLayer * layers;
        config.specularSamples = samples;
        config.wardModel = s.model;
        config.facetCache = facetCache_;
        config.unrolledLights = unrolledLights;
        config.unrolledSpecularSamples = unrolledSpec;
        const std::string source = boothShaderSource(config, settings_);
        auto program = linkProgram(kFullscreenVertexShader, source.c_str(),
                                   fmt::format("booth XYZ mode {}", mode).c_str());
        if (!program) {
            return tl::unexpected(program.error());
        }
        programs_[static_cast<std::size_t>(mode)] = std::move(*program);
    }
    vao_ = GlVertexArray::make();

    const auto texels = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
    std::vector<float> a, b;
    channelPlanes(ps, a, b);
    coeffA_ = texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, a.data());
    coeffB_ = texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, b.data());

    std::vector<float> n(relief_ ? texels * 3 : 3, 0.0f);
    if (relief_) {
        for (std::size_t i = 0; i < texels; ++i) {
            for (int k = 0; k < 3; ++k) {
                n[i * 3 + static_cast<std::size_t>(k)] = static_cast<float>(ps.normals[i][k]);
            }
        }
    } else {
        n[2] = 1.0f;
    }
    normals_ = relief_ ? texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, n.data())
                       : texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, 1, 1, n.data());

    horizon_ = horizonTexture(ps.horizon, horizonDirs_, settings_.horizonHalf);

    lightsUbo_ = GlBuffer::make();
    glBindBuffer(GL_UNIFORM_BUFFER, lightsUbo_.get());
    // Per light: position and intensity, the two spread vectors, the region's rectangle
    // (glsl/booth_interface.glsl): 16 KiB for 256 lights, the least GL_MAX_UNIFORM_BLOCK_SIZE of
    // GLES 3.1.
    glBufferData(GL_UNIFORM_BUFFER, kBoothMaxLights * 4 * 4 * sizeof(float), nullptr,
                 GL_DYNAMIC_DRAW);
    // Blocks a mode does not use are gone from its program: bound where present.
    for (const GlProgram& program : programs_) {
        const GLuint p = program.get();
        if (const GLuint block =
                    p != 0 ? glGetUniformBlockIndex(p, "BoothLights") : GL_INVALID_INDEX;
            block != GL_INVALID_INDEX) {
            glUniformBlockBinding(p, block, 0);
        }
    }

    std::vector<float> table(static_cast<std::size_t>(kBoothMaxSpecularSamples) * 4, 0.0f);
    for (int k = 0; k < samples; ++k) {
        const double u1 = (k + 0.5) / samples;
        const shading::Vec3 hl = brdf::sampleWardHalfVectorLocal(
                s.alpha, u1, shading::radicalInverse2(static_cast<unsigned>(k)));
        const double w = brdf::wardSolidAngleWithoutOh(s.alpha, hl.z, u1, samples);
        const auto i = static_cast<std::size_t>(k) * 4;
        table[i] = static_cast<float>(hl.x);
        table[i + 1] = static_cast<float>(hl.y);
        table[i + 2] = static_cast<float>(hl.z);
        table[i + 3] = static_cast<float>(w);
    }
    samplesUbo_ = GlBuffer::make();
    glBindBuffer(GL_UNIFORM_BUFFER, samplesUbo_.get());
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(table.size() * sizeof(float)),
                 table.data(), GL_STATIC_DRAW);
    for (const GlProgram& program : programs_) {
        const GLuint p = program.get();
        if (const GLuint block =
                    p != 0 ? glGetUniformBlockIndex(p, "BoothSpecSamples") : GL_INVALID_INDEX;
            block != GL_INVALID_INDEX) {
            glUniformBlockBinding(p, block, 1);
        }
    }

    // The grids' targets: the specular one shaded every frame (mode 2), the diffuse one drawn
    // whenever the cache is (mode 3).
    if (gridNodes_.x > 0) {
        if (auto ok = nodeTarget(gridNodes_, kUnitSpecGrid, "specular", gridTexture_, gridFbo_);
            !ok) {
            return ok;
        }
    }
    if (diffuseNodes_.x > 0) {
        if (auto ok = nodeTarget(diffuseNodes_, kUnitDiffGrid, "diffuse", diffuseTexture_,
                                 diffuseFbo_);
            !ok) {
            return ok;
        }
    }

    uniformAll(glProgramUniform1i, "uCoeffA", kUnitCoeffA);
    uniformAll(glProgramUniform1i, "uCoeffB", kUnitCoeffB);
    uniformAll(glProgramUniform1i, "uNormals", kUnitNormals);
    uniformAll(glProgramUniform1i, "uHorizon", kUnitHorizon);
    uniformAll(glProgramUniform1i, "uLum", kUnitLum);
    uniformAll(glProgramUniform1i, "uCache", kUnitCache);
    uniformAll(glProgramUniform1i, "uSpecGrid", kUnitSpecGrid);
    uniformAll(glProgramUniform1i, "uFacetCache", kUnitFacet);
    uniformAll(glProgramUniform2i, "uGridNodes", gridNodes_.x, gridNodes_.y);
    uniformAll(glProgramUniform1i, "uDiffGrid", kUnitDiffGrid);
    uniformAll(glProgramUniform2i, "uDiffNodes", diffuseNodes_.x, diffuseNodes_.y);
    uniformAll(glProgramUniform2i, "uTexels", s.width, s.height);
    uniformAll(glProgramUniform2f, "uSizeM", static_cast<float>(s.widthM),
               static_cast<float>(s.heightM));
    uniformAll(glProgramUniform1f, "uSoftness", static_cast<float>(settings_.horizonSoftness));
    uniformAll(glProgramUniform1f, "uLodBias", static_cast<float>(settings_.specularLodBias));
    uniformAll(glProgramUniform1f, "uLodScale",
               std::ldexp(1.0f, exactLevelTwiceBias(settings_).value_or(0)));
    uniformAll(glProgramUniform1i, "uDiffuse", settings_.diffusePass ? 1 : 0);
    uniformAll(glProgramUniform1f, "uFlareRho",
               static_cast<float>(settings_.subtractFlare ? shading::kScreenFlareRho : 0.0));
    return glCheck("uploading the scene");
}

BoothShadingPass::~BoothShadingPass() = default;

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
    std::vector<float> a, b;
    channelPlanes(ps, a, b);
    const surface::SurfaceScene& s = *ps.scene;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glBindTexture(GL_TEXTURE_2D, coeffA_.get());
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.width, s.height, GL_RGB, GL_FLOAT, a.data());
    glBindTexture(GL_TEXTURE_2D, coeffB_.get());
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.width, s.height, GL_RGB, GL_FLOAT, b.data());
    cacheValid_ = false; // the cached diffuse term was shaded from the old coefficients
    return glCheck("replacing the channel coefficients");
}

Expected<void> BoothShadingPass::setLight(const shading::PreparedLight& pl)
{
    if (pl.light == nullptr || pl.mips.levels.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "render: the booth pass needs a prepared light");
    }
    light_ = &pl;
    cacheValid_ = false;
    const booth::BoothLight& bl = *pl.light;
    const double a = bl.texelAreaM2();
    if (pl.points.size() > static_cast<std::size_t>(kBoothMaxLights)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} lights; the GL pass holds at most {}: prepare the "
                                     "light with {} or fewer",
                                     pl.points.size(), kBoothMaxLights, kBoothMaxLights));
    }
    lightCount_ = static_cast<int>(pl.points.size());
    // The block's four arrays one after another: uLight, uLightSpreadU (w: the region's mean
    // luminance), uLightSpreadV, uLightRect.
    const std::size_t block = static_cast<std::size_t>(kBoothMaxLights) * 4;
    std::vector<float> packed(block * 4, 0.0f);
    const double u2 = glm::dot(bl.edgeU, bl.edgeU);
    const double v2 = glm::dot(bl.edgeV, bl.edgeV);
    // A region's corner in the ceiling's unit coordinates (s, t in [0, 1]).
    const auto unit = [&](const shading::Vec3& q) {
        const shading::Vec3 d = q - (bl.centre - 0.5 * (bl.edgeU + bl.edgeV));
        return glm::dvec2(u2 > 0.0 ? glm::dot(d, bl.edgeU) / u2 : 0.0,
                          v2 > 0.0 ? glm::dot(d, bl.edgeV) / v2 : 0.0);
    };
    for (int i = 0; i < lightCount_; ++i) {
        const booth::PointLight& p = pl.points[static_cast<std::size_t>(i)];
        const std::size_t k = static_cast<std::size_t>(i) * 4;
        const glm::vec3 pos = f3(p.position);
        // Zero spreads leave every light's softness at uSoftness: the frames before the spread.
        const glm::vec3 su = settings_.horizonSpread ? f3(p.spreadU) : glm::vec3(0.0f);
        const glm::vec3 sv = settings_.horizonSpread ? f3(p.spreadV) : glm::vec3(0.0f);
        for (int c = 0; c < 3; ++c) {
            packed[k + static_cast<std::size_t>(c)] = pos[c];
            packed[block + k + static_cast<std::size_t>(c)] = su[c];
            packed[2 * block + k + static_cast<std::size_t>(c)] = sv[c];
        }
        packed[k + 3] = static_cast<float>(p.sumCdM2 * a);
        packed[block + k + 3] = static_cast<float>(p.meanCdM2);
        const glm::dvec2 lo = unit(p.regionOrigin);
        const glm::dvec2 hi = unit(p.regionOrigin + p.regionU + p.regionV);
        const std::array<double, 4> rect{lo.x, lo.y, hi.x, hi.y};
        for (std::size_t c = 0; c < 4; ++c) {
            packed[3 * block + k + c] = static_cast<float>(rect[c]);
        }
    }
    glBindBuffer(GL_UNIFORM_BUFFER, lightsUbo_.get());
    glBufferSubData(GL_UNIFORM_BUFFER, 0, static_cast<GLsizeiptr>(packed.size() * sizeof(float)),
                    packed.data());

    // Mip chain exactly as booth::buildMipChain made it (each level uploaded, not regenerated).
    lum_.reset();
    lum_ = GlTexture::make();
    glBindTexture(GL_TEXTURE_2D, lum_.get());
    const auto& levels = pl.mips.levels;
    lumMaxLevel_ = static_cast<int>(levels.size()) - 1;
    glTexStorage2D(GL_TEXTURE_2D, static_cast<GLsizei>(levels.size()), GL_R32F, levels[0].width,
                   levels[0].height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    std::vector<float> level;
    for (std::size_t l = 0; l < levels.size(); ++l) {
        level.assign(levels[l].cdM2.begin(), levels[l].cdM2.end());
        glTexSubImage2D(GL_TEXTURE_2D, static_cast<GLint>(l), 0, 0, levels[l].width,
                        levels[l].height, GL_RED, GL_FLOAT, level.data());
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, lumMaxLevel_);
    nearest(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    if (hwFilter_) {
        // booth::MipChain::sample's rule (glsl/mip_chain.glsl lumSample); border colour 0.
        constexpr GLenum kClampToBorder = 0x812D; // GL_CLAMP_TO_BORDER_EXT / _OES
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER,
                        settings_.specularNearestLevel ? GL_LINEAR_MIPMAP_NEAREST
                                                       : GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, kClampToBorder);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, kClampToBorder);
    }

    const surface::SurfaceScene& s = *scene_->scene;
    specXyz_ = colour::spectrumToXyz(*observer_, s.rhoS * pl.unitSpd);
    uniformAll(glProgramUniform1i, "uLightCount", lightCount_);
    set3All("uLightNormal", bl.normal());
    uniformAll(glProgramUniform1f, "uTexelArea", static_cast<float>(a));
    std::array<float, colour::kChannels * 3> m{};
    for (std::size_t k = 0; k < colour::kChannels; ++k) {
        for (int c = 0; c < 3; ++c) {
            m[k * 3 + static_cast<std::size_t>(c)] = static_cast<float>(pl.channelXyz[k][c]);
        }
    }
    uniformAll(glProgramUniform3fv, "uChannelXyz", static_cast<GLsizei>(colour::kChannels),
               m.data());
    set3All("uWhite", pl.white);
    set3All("uSpecXyz", specXyz_);
    set3All("uLightCentre", bl.centre);
    set3All("uEdgeU", bl.edgeU);
    set3All("uEdgeV", bl.edgeV);
    uniformAll(glProgramUniform2f, "uInvEdge2", static_cast<float>(u2 > 0.0 ? 1.0 / u2 : 0.0),
               static_cast<float>(v2 > 0.0 ? 1.0 / v2 : 0.0));
    uniformAll(glProgramUniform1i, "uLumMaxLevel", lumMaxLevel_);
    uniformAll(glProgramUniform2i, "uLumSize", levels[0].width, levels[0].height);
    uniformAll(glProgramUniform2f, "uLumUsed", static_cast<float>(pl.mips.usedU),
               static_cast<float>(pl.mips.usedV));
    return glCheck("uploading the light");
}

void BoothShadingPass::setSurroundIlluminance(bool on) const
{
    if (on != surroundIlluminance_) {
        surroundIlluminance_ = on;
        cacheValid_ = false;
    }
}

void BoothShadingPass::set3All(const char* name, const glm::dvec3& v) const
{
    const glm::vec3 f = f3(v);
    uniformAll(glProgramUniform3f, name, f.x, f.y, f.z);
}

void BoothShadingPass::usePose(int mode, const shading::PanelPose& panel) const
{
    const GLuint p = programs_[static_cast<std::size_t>(mode)].get();
    const auto set = [p](const char* name, const shading::Vec3& v) {
        const glm::vec3 f = f3(v);
        glProgramUniform3f(p, glGetUniformLocation(p, name), f.x, f.y, f.z);
    };
    set("uCentre", panel.centre);
    set("uRight", panel.right);
    set("uUp", panel.up);
    set("uNormal", panel.normal);
    glUseProgram(p);
}

Expected<void> BoothShadingPass::ensureCacheTarget(int width, int height) const
{
    if (caches_[0].texture && cacheWidth_ == width && cacheHeight_ == height) {
        return {};
    }
    for (CacheBuffer& c : caches_) {
        c = CacheBuffer{}; // a new texture holds nothing yet
    }
    facetTexture_.reset();
    front_ = 0;
    pending_.reset();
    glActiveTexture(GL_TEXTURE0 + kUnitCache); // texture2d binds it: not over another input
    if (facetCache_) {
        facetTexture_ = texture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, width, height, nullptr);
    }
    // The back cache only where refreshes are sliced: 9 MB at 960x600 that nothing else reads.
    const int buffers = settings_.cacheSlices > 1 ? 2 : 1;
    bool complete = true;
    for (int b = 0; b < buffers; ++b) {
        CacheBuffer& c = caches_[static_cast<std::size_t>(b)];
        c.texture = texture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, width, height, nullptr);
        glBindTexture(GL_TEXTURE_2D, 0);
        c.fbo = GlFramebuffer::make();
        glBindFramebuffer(GL_FRAMEBUFFER, c.fbo.get());
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, c.texture.get(),
                               0);
        if (facetCache_) {
            // Mode 0 writes the facet normal beside the cached terms; the blit reads attachment 0.
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D,
                                   facetTexture_.get(), 0);
            const std::array<GLenum, 2> attachments{GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
            glDrawBuffers(2, attachments.data());
            glReadBuffer(GL_COLOR_ATTACHMENT0);
        }
        complete = complete && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    cacheWidth_ = width;
    cacheHeight_ = height;
    cacheValid_ = false;
    if (!complete) {
        return makeError(ErrorCode::Unsupported,
                         "render: the booth pass's RGBA32F cache is not renderable on this GL");
    }
    return glCheck("creating the booth pass's cache");
}

void BoothShadingPass::drawCacheSlice(int buffer,
                                      const shading::PanelPose& pose,
                                      int slice,
                                      int slices,
                                      const PixelRect& rect,
                                      int width,
                                      int height) const
{
    CacheBuffer& c = caches_[static_cast<std::size_t>(buffer)];
    if (slice == 0 && diffuseNodes_.x > 0) {
        // E_geo at the diffuse grid's nodes, for mode 0 to interpolate on the surface (it stays
        // for the refresh's later bands: nothing else draws into it).
        glBindFramebuffer(GL_FRAMEBUFFER, diffuseFbo_.get());
        glViewport(0, 0, diffuseNodes_.x, diffuseNodes_.y);
        usePose(3, pose);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glViewport(0, 0, width, height);
    }
    if (diffuseNodes_.x > 0) {
        glActiveTexture(GL_TEXTURE0 + kUnitDiffGrid);
        glBindTexture(GL_TEXTURE_2D, diffuseTexture_.get());
        glActiveTexture(GL_TEXTURE0);
    }
    // Every pixel: the diffuse term on the surface, E_geo on the whole panel (the flare); or,
    // without the surround's illuminance, the surface's rectangle and zero around it.
    glBindFramebuffer(GL_FRAMEBUFFER, c.fbo.get());
    PixelRect region{0, 0, width, height};
    if (!surroundIlluminance_) {
        // Mode 0 writes only the rectangle, so zero around it stays zero from one refresh to
        // the next: cleared only when the cache was not already zero there (a new target, a
        // new rectangle, or the surround's illuminance drawn). On llvmpipe a clear of the
        // RGBA32F cache is a pass over 9 MB at 960x600, a good part of a tilting frame.
        if (slice == 0 && !(c.zeroAround && *c.zeroAround == rect)) {
            const std::array<float, 4> zero{};
            glClearBufferfv(GL_COLOR, 0, zero.data());
            c.zeroAround = rect;
        }
        region = rect;
    } else {
        c.zeroAround.reset();
    }
    // Band 'slice' of the region's rows: the surface's rows split evenly (they carry nearly all
    // the cost), the rows below it with the first band and those above with the last.
    int y0 = region.y;
    int y1 = region.y + region.height;
    if (slices > 1) {
        const auto edge = [&](int k) {
            return rect.y + static_cast<int>(static_cast<long>(rect.height) * k / slices);
        };
        y0 = slice == 0 ? region.y : edge(slice);
        y1 = slice == slices - 1 ? region.y + region.height : edge(slice + 1);
    }
    glEnable(GL_SCISSOR_TEST);
    glScissor(region.x, y0, region.width, std::max(y1 - y0, 0));
    usePose(0, pose);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_SCISSOR_TEST);
    if (diffuseNodes_.x > 0) {
        glActiveTexture(GL_TEXTURE0 + kUnitDiffGrid);
        glBindTexture(GL_TEXTURE_2D, 0); // not sampled while mode 3 draws into it
        glActiveTexture(GL_TEXTURE0);
    }
}

Expected<void> BoothShadingPass::draw(const shading::View& view,
                                      int width,
                                      int height,
                                      const SurfaceLayout& layout,
                                      const shading::PanelPose* cachePose) const
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
    const auto restore = [&] { glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target)); };
    if (auto ok = ensureCacheTarget(width, height); !ok) {
        restore();
        return ok;
    }
    glViewport(0, 0, width, height);
    glBindVertexArray(vao_.get());
    uniformAll(glProgramUniform2f, "uViewport", static_cast<float>(width),
               static_cast<float>(height));
    uniformAll(glProgramUniform2f, "uSurfOffset", static_cast<float>(layout.offset.x),
               static_cast<float>(layout.offset.y));
    uniformAll(glProgramUniform2f, "uSurfScale", static_cast<float>(layout.scale.x),
               static_cast<float>(layout.scale.y));
    // The same rectangle in window pixels (u = 0 to 1 left to right, v = 0 to 1 top to bottom):
    // the default layout's are whole numbers, (0, height, width, height).
    const glm::dvec2 sx = glm::max(layout.scale, glm::dvec2(1e-9));
    uniformAll(glProgramUniform4f, "uSurfPixels",
               static_cast<float>(-layout.offset.x * width / sx.x),
               static_cast<float>(height * (1.0 + layout.offset.y / sx.y)),
               static_cast<float>(width / sx.x), static_cast<float>(height / sx.y));
    set3All("uEye", view.eye);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, lightsUbo_.get());
    glBindBufferBase(GL_UNIFORM_BUFFER, 1, samplesUbo_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitCoeffA);
    glBindTexture(GL_TEXTURE_2D, coeffA_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitCoeffB);
    glBindTexture(GL_TEXTURE_2D, coeffB_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitNormals);
    glBindTexture(GL_TEXTURE_2D, normals_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitHorizon);
    glBindTexture(GL_TEXTURE_2D_ARRAY, horizon_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitLum);
    glBindTexture(GL_TEXTURE_2D, lum_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitCache);
    glBindTexture(GL_TEXTURE_2D, 0); // not sampled while it is the render target

    const shading::PanelPose& diffusePose = cachePose != nullptr ? *cachePose : view.panel;
    // What the surface can light (the whole viewport for a layout that does not scale): what the
    // compose draws, and all the cache holds without the surround's illuminance.
    const PixelRect rect = surfaceRect(layout, width, height);
    const CacheKey key{diffusePose.centre,
                       diffusePose.right,
                       diffusePose.up,
                       diffusePose.normal,
                       width,
                       height,
                       layout.offset,
                       layout.scale};
    const int slices = std::max(settings_.cacheSlices, 1);
    // Only a new pose is drawn in bands: the compose places the surface by this draw's layout,
    // and the facet normals (one texture behind both caches) follow the layout too, so a cache
    // of another layout or size is no frame to show meanwhile.
    const bool samePlacement = key.width == cacheKey_.width && key.height == cacheKey_.height &&
                               key.offset == cacheKey_.offset && key.scale == cacheKey_.scale;
    if (!cacheValid_ || (!(key == cacheKey_) && (slices == 1 || !samePlacement))) {
        // Drawn whole: the first cache, a new light, size, layout, channels or surround (nothing
        // of the old cache would do), or any change with unsliced refreshes.
        pending_.reset();
        drawCacheSlice(front_, diffusePose, 0, 1, rect, width, height);
        cacheKey_ = key;
        cacheValid_ = true;
        ++cacheRefreshes_;
    } else {
        if (!pending_ && !(key == cacheKey_)) {
            pending_ = PendingRefresh{key, diffusePose, 0};
        }
        if (pending_) {
            // One band of the refresh into the back cache; the last one makes it the front.
            const int back = 1 - front_;
            drawCacheSlice(back, pending_->pose, pending_->nextSlice, slices, rect, width, height);
            if (++pending_->nextSlice == slices) {
                front_ = back;
                cacheKey_ = pending_->key;
                pending_.reset();
                ++cacheRefreshes_;
            }
        }
    }
    if (gridNodes_.x > 0) {
        // This eye's specular term at the grid's nodes, for the compose to interpolate.
        glBindFramebuffer(GL_FRAMEBUFFER, gridFbo_.get());
        glViewport(0, 0, gridNodes_.x, gridNodes_.y);
        usePose(2, view.panel);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glViewport(0, 0, width, height);
    }
    // The frame is the cache around the surface ((0, 0, 0) and E_geo) and, without a specular
    // term or flare to add, on it too: copy it. Then compose the surface's rectangle (widened by a
    // pixel so that the shader's own bounds test decides every edge pixel): the cached part, the
    // specular term for this frame's pose and eye, minus the flare.
    const CacheBuffer& front = caches_[static_cast<std::size_t>(front_)];
    glBindFramebuffer(GL_READ_FRAMEBUFFER, front.fbo.get());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(target));
    glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    restore();
    if (specular_ || settings_.subtractFlare) {
        glEnable(GL_SCISSOR_TEST);
        glScissor(rect.x, rect.y, rect.width, rect.height);
        usePose(1, view.panel);
        glActiveTexture(GL_TEXTURE0 + kUnitCache);
        glBindTexture(GL_TEXTURE_2D, front.texture.get());
        glActiveTexture(GL_TEXTURE0 + kUnitFacet);
        glBindTexture(GL_TEXTURE_2D, facetTexture_.get());
        glActiveTexture(GL_TEXTURE0 + kUnitSpecGrid);
        glBindTexture(GL_TEXTURE_2D, gridTexture_.get());
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindTexture(GL_TEXTURE_2D, 0);
        glActiveTexture(GL_TEXTURE0 + kUnitFacet);
        glBindTexture(GL_TEXTURE_2D, 0);
        glActiveTexture(GL_TEXTURE0 + kUnitCache);
        glBindTexture(GL_TEXTURE_2D, 0);
        glDisable(GL_SCISSOR_TEST);
    }
    glActiveTexture(GL_TEXTURE0);
    return glCheck("drawing the booth pass");
}

} // namespace replica::pipeline::render
