// The booth shading pass on the GPU: a booth-lit surface scene rendered to absolute XYZ (cd/m^2)
// in GLES 3.1 fragment shaders, following shading/realtime_model.h (the executable specification).
// Needs a current GLES 3.1 context on the calling thread for every call, including destruction.
#pragma once

#include <array>
#include <memory>
#include <optional>

#include <GLES3/gl31.h>
#include <glm/vec2.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/render/pixel_rect.h>
#include <pipeline/render/xyz_target.h>
#include <pipeline/scene/stand.h>
#include <pipeline/shading/frame.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/view.h>

namespace replica::pipeline::render {

// Which part of the surface a framebuffer pixel shows: surface (u, v) = offset + scale * pixel
// (u, v), v down the image; pixels that land outside [0, 1]^2 are black. {0, 0}, {1, 1}: the frame
// covers the surface exactly, as shading::View does.
struct SurfaceLayout {
    glm::dvec2 offset{0.0, 0.0};
    glm::dvec2 scale{1.0, 1.0};
};

// The pixels of a width x height frame that can show the surface, widened by one pixel so that
// the shader's own bounds test decides every edge pixel: outside it the booth pass writes XYZ
// (0, 0, 0), the black panel around the surface. The whole frame for a layout that does not scale.
PixelRect surfaceRect(const SurfaceLayout& layout, int width, int height);

// The surface at its physical size, centred on the panel's active area (the appliance's frame
// covers the whole panel). The matching View's panel centre is the active area's centre.
SurfaceLayout layoutOnPanel(const surface::SurfaceScene& scene, const scene::StandModel& stand);

class BoothShadingPass
{
public:
    // Uploads the scene's textures: K = 6 coefficients per texel in the basis the scene was
    // prepared with, normal map and horizon map (when the settings use them). The settings stay
    // fixed for the pass's life; 'scene' and 'obs' must outlive it.
    static Expected<std::unique_ptr<BoothShadingPass>>
    create(const shading::PreparedScene& scene,
           const shading::RenderSettings& settings,
           const colour::Observer& obs);
    ~BoothShadingPass();
    BoothShadingPass(const BoothShadingPass&) = delete;
    BoothShadingPass& operator=(const BoothShadingPass&) = delete;

    // Replaces the per-texel channel coefficients with those of 'scene' (the same surface with its
    // palette projected onto another basis: a light-adaptive re-encode). Synchronous: the next
    // draw uses them. The next setLight must carry XYZ vectors of the new basis. 'scene' must
    // outlive the pass or the next call.
    Expected<void> setChannels(const shading::PreparedScene& scene);

    // Uploads a light: its median-cut point lights (at most 256), luminance mip chain and
    // per-channel XYZ vectors (prepared in the scene's basis). 'light' must outlive the pass or the
    // next call.
    Expected<void> setLight(const shading::PreparedLight& light);

    // Draws into the bound framebuffer (viewport width x height, an RGBA32F colour target): XYZ
    // (cd/m^2) and, in alpha, E_geo (lux on the panel plane, every pixel: pass 2's flare term).
    // The eye-independent part (eq. 1 and 2, E_geo) is kept in a cache of the viewport's size and
    // recomputed only when the light, the size, the layout or its pose differs from the cached
    // one (exactly), or after invalidateCache(); its pose is cachePose when given (a pose held
    // against sensor noise: booth_scene_pass.h), else view.panel. Every draw then adds the
    // specular term for view.eye and view.panel. A frame drawn from the cache is bit-identical
    // to one that recomputes it.
    // With settings.cacheSlices = K > 1 a pose change (the panel tilted) recomputes the cache in
    // K bands of rows over K draws into a second cache, while the draws compose from the complete
    // cache they have; the K-th draw swaps the two and composes from the new one. A pose change
    // during those K draws waits for them (the bands all belong to one pose), so the diffuse term
    // shown is always one whole cache, at most 2K - 2 draws behind the pose asked for. A first
    // cache, and any change of light, size, layout, channels or surround, is drawn whole at once as
    // with K = 1. Once the pose holds still the frames are those of K = 1, bit for bit.
    Expected<void> draw(const shading::View& view,
                        int width,
                        int height,
                        const SurfaceLayout& layout = {},
                        const shading::PanelPose* cachePose = nullptr) const;

    // Forces the next draw to recompute the cached part (e.g. after the channel encoding of the
    // scene's textures changed under the pass).
    void invalidateCache() const { cacheValid_ = false; }
    // Whether the cache (and so every frame) carries E_geo around the surface, what a display pass
    // that shades the whole panel needs for its flare (the default). Off, the pass shades only the
    // surface's rectangle (surfaceRect) and the frame is (0, 0, 0, 0) around it: for a display pass
    // that clears that surround anyway (DisplayPass::surroundConstant). Inside the rectangle the
    // frame is the same either way.
    void setSurroundIlluminance(bool on) const;
    bool surroundIlluminance() const { return surroundIlluminance_; }
    // How many times the cached part was recomputed so far (a sliced refresh counts once, at the
    // draw that completes it).
    long cacheRefreshes() const { return cacheRefreshes_; }
    // Whether a sliced refresh is under way (some of its bands drawn, the cache shown the old one).
    bool cacheRefreshPending() const { return pending_.has_value(); }

    const shading::RenderSettings& settings() const { return settings_; }
    const shading::PreparedScene& scene() const { return *scene_; }
    // Whether the luminance chain is filtered by the sampler (settings.hardwareFilter and the
    // GL's float-filtering and border-clamp extensions) or by hand in the shader.
    bool hardwareFilter() const { return hwFilter_; }

private:
    BoothShadingPass() = default;
    Expected<void> init(const shading::PreparedScene& scene);
    Expected<void> ensureCacheTarget(int width, int height) const;
    // Draws the cache's eye-independent part at 'pose' into caches_[buffer]: band 'slice' of
    // 'slices' (slice 0 also draws the diffuse grid and clears what needs clearing).
    void drawCacheSlice(int buffer,
                        const shading::PanelPose& pose,
                        int slice,
                        int slices,
                        const PixelRect& rect,
                        int width,
                        int height) const;
    // Sets the panel pose in one mode's program and makes that program current: each mode draws
    // at its own pose (the cache at the held one).
    void usePose(int mode, const shading::PanelPose& panel) const;

    shading::RenderSettings settings_;
    const shading::PreparedScene* scene_ = nullptr;
    const shading::PreparedLight* light_ = nullptr;
    const colour::Observer* observer_ = nullptr;
    bool relief_ = false;
    bool specular_ = false; // a specular term to shade: glossy scene, pass and samples on
    bool hwFilter_ = false;
    int horizonDirs_ = 0;
    int lightCount_ = 0;
    int lumMaxLevel_ = 0;
    colour::Xyz specXyz_{0.0};
    // One program per shader mode (booth_shaders.h): 0 cache, 1 compose, 2 specular grid,
    // 3 diffuse grid (0 where the pass has no diffuse grid).
    std::array<GlProgram, 4> programs_{};
    // Sets a uniform in every mode's program (where that mode still has it).
    template <typename Fn, typename... Args>
    void uniformAll(Fn fn, const char* name, Args... args) const
    {
        for (const GlProgram& program : programs_) {
            if (const GLuint p = program.get(); p != 0) {
                fn(p, glGetUniformLocation(p, name), args...);
            }
        }
    }
    void set3All(const char* name, const glm::dvec3& v) const;
    GlVertexArray vao_;
    GlBuffer lightsUbo_;
    GlBuffer samplesUbo_;
    GlTexture coeffA_, coeffB_, normals_, horizon_, lum_;

    // The cache of the eye-independent part and what it was drawn for.
    struct CacheKey {
        shading::Vec3 centre{0.0}, right{0.0}, up{0.0}, normal{0.0};
        int width = 0, height = 0;
        glm::dvec2 offset{0.0}, scale{0.0};
        bool operator==(const CacheKey&) const = default;
    };
    // cacheKey_: what the front cache (caches_[front_]) holds when cacheValid_.
    mutable CacheKey cacheKey_;
    mutable bool cacheValid_ = false;
    mutable bool surroundIlluminance_ = true;
    mutable long cacheRefreshes_ = 0;
    struct CacheBuffer {
        GlTexture texture; // RGBA32F: diffuse XYZ, E_geo in alpha
        GlFramebuffer fbo;
        // The rectangle outside which this buffer is known to hold zero (cleared for it, and mode
        // 0 writes only inside it); none after a new texture or a draw with the surround's
        // illuminance.
        std::optional<PixelRect> zeroAround;
    };
    // The front cache the frames compose from, and (settings.cacheSlices > 1 only) the back one
    // a sliced refresh draws into.
    mutable std::array<CacheBuffer, 2> caches_{};
    mutable int front_ = 0;
    // A sliced refresh under way: the key and pose it draws, and its next band.
    struct PendingRefresh {
        CacheKey key;
        shading::PanelPose pose;
        int nextSlice = 0;
    };
    mutable std::optional<PendingRefresh> pending_;
    // With relief and a per-pixel specular term the cache also keeps each pixel's facet normal
    // (tangent frame, what bilinearNormal gives; RGBA32F), so that the compose reads one texel
    // instead of four and their normalisation every frame. One texture behind both caches: a
    // facet normal depends on the layout and size alone, and a change of either redraws the
    // cache whole, so a band drawn into the back cache writes there what it already holds.
    bool facetCache_ = false;
    mutable GlTexture facetTexture_;
    mutable int cacheWidth_ = 0, cacheHeight_ = 0;

    // The specular grid (settings.specularGrid > 0 on a glossy scene): its nodes and target.
    shading::GridNodes gridNodes_;
    GlTexture gridTexture_;
    GlFramebuffer gridFbo_;
    // The diffuse grid (settings.diffuseGrid > 0 on a flat surface): drawn with the cache.
    shading::GridNodes diffuseNodes_;
    GlTexture diffuseTexture_;
    GlFramebuffer diffuseFbo_;
};

} // namespace replica::pipeline::render
