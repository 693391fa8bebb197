// The booth shading pass on the GPU: a booth-lit surface scene rendered to absolute XYZ (cd/m^2)
// in GLES 3.1 fragment shaders, following shading/realtime_model.h (the executable specification).
// Its parts: the programs (booth_programs.h), what they read (booth_inputs.h), the cache of the
// eye-independent part (booth_diffuse_cache.h), the specular term (booth_specular.h) and the
// compose (booth_compose.h); this class owns them and says when each runs.
// Needs a current GLES 3.1 context on the calling thread for every call, including destruction.
#pragma once

#include <memory>

#include <pipeline/base/expected.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/render/booth_diffuse_cache.h>
#include <pipeline/render/booth_inputs.h>
#include <pipeline/render/booth_programs.h>
#include <pipeline/render/booth_specular.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/render/pixel_rect.h>
#include <pipeline/render/surface_layout.h>
#include <pipeline/render/xyz_target.h>
#include <pipeline/shading/frame.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/view.h>

namespace replica::pipeline::render {

// How many lights and specular samples the pass's programs write out, where they write them out
// (per pixel: the lights on a flat surface without the diffuse grid, the samples without the
// specular grid), and not as many as the settings say: a pass that lamps of several counts share
// (booth_scene_pass.h) writes out the fewest of them, each lamp looping to its own count. Not the
// most, each kept to the count: llvmpipe runs such an `if` under a mask, so every lamp would pay
// for the most samples (tried: the glossy cylinder's median frame 25 -> 31-51 ms under load).
struct BoothUnroll {
    int lights = -1;          // -1: settings.lights
    int specularSamples = -1; // -1: settings.specularSamples
};

class BoothShadingPass
{
public:
    // Uploads the scene's textures: K = 6 coefficients per texel in the basis the scene was
    // prepared with, normal map and horizon map (when the settings use them). The settings stay
    // fixed for the pass's life but for the counts setCounts changes; 'scene' and 'obs' must
    // outlive it.
    static Expected<std::unique_ptr<BoothShadingPass>>
    create(const shading::PreparedScene& scene,
           const shading::RenderSettings& settings,
           const colour::Observer& obs,
           BoothUnroll unroll = {});

    ~BoothShadingPass();
    BoothShadingPass(const BoothShadingPass&) = delete;
    BoothShadingPass& operator=(const BoothShadingPass&) = delete;

    // Replaces the per-texel channel coefficients with those of 'scene' (the same surface with its
    // palette projected onto another basis: a light-adaptive re-encode). Synchronous: the next
    // draw uses them. The next setLight must carry XYZ vectors of the new basis. 'scene' must
    // outlive the pass or the next call.
    Expected<void> setChannels(const shading::PreparedScene& scene);

    // The counts the programs read at run time, without compiling anything: the lights the next
    // setLight's light is prepared with (settings().lights; the shader loops to the light's own
    // count) and the specular samples (the sample table and its count; a pass made without a
    // specular term takes none, one made with it as many as its programs write out, at least 1,
    // to kBoothMaxSpecularSamples). A frame drawn after it is the frame a pass made with these
    // counts draws.
    Expected<void> setCounts(int lights, int specularSamples);

    // Uploads a light: its median-cut point lights (at most 256), luminance mip chain and
    // per-channel XYZ vectors (prepared in the scene's basis). 'light' must outlive the pass or the
    // next call.
    Expected<void> setLight(const shading::PreparedLight& light);

    // Draws into the bound framebuffer (viewport width x height, an RGBA32F colour target): XYZ
    // (cd/m^2) and, in alpha, E_geo (lux on the panel plane, every pixel: pass 2's flare term).
    // The eye-independent part (eq. 1 and 2, E_geo) is kept in a cache of the viewport's size
    // (booth_diffuse_cache.h) and drawn again only where it does not hold what 'cache' names
    // (the term shown and, a sliced refresh under way, band b of K of the term at another pose,
    // drawn into a second buffer that the last band makes the one shown: what the state stage
    // decided, booth_scene_pass.h); without 'cache', the term whole at view.panel. A change of
    // light, size, layout, channels or surround draws it whole. Every draw then adds the specular
    // term for view.eye and view.panel. A frame drawn from the cache is bit-identical to one that
    // recomputes it, and a band is the same pixels as that band of the whole term.
    Expected<void> draw(const shading::View& view,
                        int width,
                        int height,
                        const SurfaceLayout& layout = {},
                        const CacheWant* cache = nullptr);

    // Forces the next draw to recompute the cached part (e.g. after the channel encoding of the
    // scene's textures changed under the pass).
    void invalidateCache() { cache_.invalidate(); }
    // Whether the cache (and so every frame) carries E_geo around the surface, what a display pass
    // that shades the whole panel needs for its flare (the default). Off, the pass shades only the
    // surface's rectangle (surfaceRect) and the frame is (0, 0, 0, 0) around it: for a display pass
    // that clears that surround anyway (DisplayPass::surroundConstant). Inside the rectangle the
    // frame is the same either way.
    void setSurroundIlluminance(bool on) { cache_.setSurroundIlluminance(on); }
    bool surroundIlluminance() const { return cache_.surroundIlluminance(); }
    // How many times the cached part was recomputed so far (a sliced refresh counts once, at the
    // draw that completes it).
    long cacheRefreshes() const { return cache_.refreshes(); }
    // Whether a sliced refresh is under way (some of its bands drawn, the cache shown the old one).
    bool cacheRefreshPending() const { return cache_.refreshPending(); }

    const shading::RenderSettings& settings() const { return settings_; }
    const shading::PreparedScene& scene() const { return *scene_; }
    // Whether the luminance chain is filtered by the sampler (where the GL has the
    // float-filtering and border-clamp extensions) or by hand in the shader.
    bool hardwareFilter() const { return hwFilter_; }
    // The specular samples the programs write out one by one (0: none, the samples loop): the
    // fewest setCounts takes.
    int writtenOutSamples() const { return unrolledSamples_; }

private:
    BoothShadingPass() = default;
    Expected<void> init(const shading::PreparedScene& scene, BoothUnroll unroll);

    shading::RenderSettings settings_;
    const shading::PreparedScene* scene_ = nullptr;
    const shading::PreparedLight* light_ = nullptr;
    const colour::Observer* observer_ = nullptr;
    bool specular_ = false;   // a specular term to shade: glossy scene, pass and samples on
    int unrolledSamples_ = 0; // the specular samples written out in the programs
    bool hwFilter_ = false;
    BoothPrograms programs_;
    GlVertexArray vao_;
    BoothInputs inputs_;
    BoothSpecular specularTerm_;
    BoothDiffuseCache cache_;
};

} // namespace replica::pipeline::render
