// The booth pass driven by the frame's scene state, upload + draw: the classified lamp picks the
// booth light (its measured luminance image), an unknown light becomes a uniform emitter with the
// sensed spectrum (the paper's direct-sensor mode); the eye comes from the tracker, the panel pose
// from the tilt through the stand's hinge model, the cached diffuse term's from the state's
// diffuse term and its refresh band; with a light-adaptive encoder the surface is in the state's
// encoding. It keeps no history and no schedule: what it holds on the GPU (light, encoding,
// caches) is labelled with what it holds, and a fresh pass given any frame's state draws that
// frame bit for bit (the state stage, state/, decides what carries from frame to frame).
// Needs a current GLES 3.1 context for every call.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pipeline/booth/booth_model.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/scene_state.h>
#include <pipeline/spectral/adaptive_encoding.h>

namespace replica::pipeline::render {

// One lamp's own counts (the planner in the loop, platform/render_plan.h); the rest of the
// settings stay BoothSceneSetup::settings.
struct LampSettings {
    int lights = 32;
    int specularSamples = 24;  // glossy scenes only
    int horizonDirections = 8; // scenes with relief only; 0 keeps the setup's
    bool walls = true;         // a booth with walls only: light this lamp's passes with them
};

// The wall patches' side the appliance solves a booth's walls with: 35 cm, each wall two to
// three patches, the panel's share of them (shading::wallField) a few tens of microseconds per
// pose; against the exact reference (5 cm patches) it adds no ΔE00 measurable above the
// renderer's own error (docs/rendering.md, "The booth's walls").
inline constexpr double kRealtimeWallPatchM = 0.35;

struct BoothSceneSetup {
    booth::Booth booth; // lights with luminance images (data/booth); lampIndex indexes them
    surface::SurfaceScene scene;
    colour::ChannelBasis basis;
    colour::Observer observer;
    scene::StandModel stand;
    shading::RenderSettings settings;
    // Basis "adaptive_k6": when set, 'basis' is the encoder's general basis, what a state of
    // encoding 0 draws with; a state of encoding n > 0 carries its basis (the light estimator
    // decides, state/light_estimator.h), and the surface is re-encoded for it.
    std::shared_ptr<const spectral::AdaptiveEncoder> adaptive;
    // The booth dimmer (platform/booth_dimmer.h) for the direct-sensor mode's uniform emitter:
    // the sensed luminance times this. The booth's own lamps come already scaled in 'booth'.
    double luminanceScale = 1.0;
    // Per lamp name: its own lights, specular samples and horizon directions. A lamp not named
    // here, and the direct-sensor mode, draw with 'settings'. Each distinct program (horizon
    // directions, walls, a specular term or none) gets a shading pass of its own, built by
    // create(); lamps that differ only in their counts of lights and specular samples share one,
    // which takes each lamp's counts at the switch; a lamp change switches to its pass.
    std::map<std::string, LampSettings> perLamp;
    // The scene already prepared (shading::prepareScene) with settings.horizonDirections, when the
    // caller had to prepare it before the pass (the automatic dimmer's probe views): a pass with
    // that many horizon directions copies its normals and horizons rather than computing them
    // again before the first frame.
    std::shared_ptr<const shading::PreparedScene> prepared;
    // The lamp (index into booth.lights) the first frame most likely shows (the site's default
    // lamp, before the first spectrum): its pass is the one made at create(), so that the first
    // frame makes no other; -1: variant 0's (setup's settings), as the direct-sensor mode draws.
    int firstLamp = -1;
};

class BoothScenePass
{
public:
    static Expected<std::unique_ptr<BoothScenePass>> create(BoothSceneSetup setup);

    // Draws the state's frame into the bound RGBA32F framebuffer (viewport width x height, the
    // whole panel; the surface at its physical size in the middle, black around it; alpha: the
    // illuminance on the panel, lux). Everything it draws is what the state names: the light (by
    // its content key, scene::lightKey), the encoding, the specular term at the state's tilt and
    // eye, and the cached diffuse term at state.diffuse's tilt with the band of a sliced refresh
    // it names (the state stage decides the schedule: pipeline/scene/diffuse_schedule.h; this
    // pass holds the buffers, BoothDiffuseCache). Where the buffers do not hold what the state
    // says (a fresh pass, frame N of a recording drawn alone) they are drawn first: the frame is
    // the same.
    Expected<void> draw(const scene::SceneState& state, int width, int height);

    // The pixels of a width x height frame that can show the surface; draw() writes XYZ (0, 0, 0)
    // everywhere else (render::surfaceRect).
    PixelRect surfaceRect(int width, int height) const;

    // The pass's cache of the eye-independent part (booth_shading_pass.h): how often it was
    // recomputed, and a way to force it (e.g. after the channel encoding changed).
    long cacheRefreshes() const;
    void invalidateCache();
    // BoothShadingPass::setSurroundIlluminance.
    void setSurroundIlluminance(bool on);
    bool surroundIlluminance() const { return pass_->surroundIlluminance(); }

    std::string description() const;
    // What the pass was made from (the scene, the booth, the stand, the observer): what the error
    // probe evaluates the exact reference with.
    const BoothSceneSetup& setup() const { return setup_; }

    // Draws every shading pass once (one per distinct program, each with a lamp that uses
    // it) into a width x height target of its own, so that the shaders' first-use compilation
    // (llvmpipe compiles a program's code at its first draw, 0.7-10 s for the booth pass) happens
    // here, before the loop's first frame, and not at the first switch to each lamp. Give it the
    // frame's size: llvmpipe compiles a variant per texture shape (power-of-two sides or not), so
    // a target of another shape may leave the frame's variant to compile at the switch. Leaves
    // every frame as it would be without (each pass is given its lamp's light again before it
    // draws; booth_warm_up_test.cpp) and cacheRefreshes() as it was. Returns how long it took, ms.
    Expected<double> warmUp(int width, int height);
    // warmUp for shading pass v alone (drawn with a lamp that uses it): what the appliance does in
    // the loop's idle time for the passes the first frame did not need. The active pass's light
    // and cache stay as they were unless v is the active pass (then its light is selected afresh
    // at the next draw); frames and cacheRefreshes() as without. Returns how long it took, ms.
    Expected<double> warmUpVariant(std::size_t v, int width, int height);
    // How many shading passes there are (one per distinct program).
    std::size_t variantCount() const { return variants_.size(); }
    // The shading passes not drawn yet in this context (neither by a frame nor by a warm-up):
    // each compiles its shaders at its first draw. The lamps' first, in lamp order.
    std::vector<std::size_t> variantsNotDrawn() const;
    // The frames whose draw was their shading pass's first (its shaders compiled in the frame: a
    // lamp switch to a pass not warmed up, or the first frame), and the last such draw's time, ms.
    long firstUseDraws() const { return firstUseDraws_; }
    double lastFirstUseMs() const { return lastFirstUseMs_; }

    // The basis the surface is encoded in now, and the encoding it is (SceneState::encoding: 0
    // without an adaptive encoder or before its first light).
    const colour::ChannelBasis& basis() const { return basis_; }
    int encodings() const { return encodings_; }

private:
    BoothScenePass() = default;
    // Uploads the state's light when it changed or differs from the one on the GPU.
    Expected<void> selectLight(const scene::SceneState& state);
    // Re-encodes the surface in the state's encoding when the GPU holds another (the palette
    // re-projected onto the state's basis, the coefficient textures replaced).
    Expected<void> applyEncoding(const scene::SceneState& state);

    // One shading pass per distinct program (variants_[0]: setup_.settings'), each with the scene
    // prepared for its horizon directions; lamps that differ only in their counts of lights and
    // specular samples share one, made with the settings of the first of them and written out for
    // the fewest counts ('unroll'); 'encodings' is the encoding its channels hold. Only the
    // first lamp's (BoothSceneSetup::firstLamp) or variant 0 is made at create(); another has no
    // scene or pass until makeVariant.
    struct Variant {
        shading::RenderSettings settings;
        BoothUnroll unroll;
        std::unique_ptr<shading::PreparedScene> prepared;
        std::unique_ptr<BoothShadingPass> pass;
        int encodings = 0;
    };
    // Makes variant v the one drawn (made first when it was not: makeVariant), its channels
    // brought up to date.
    Expected<void> useVariant(std::size_t v);
    // Prepares variant v's scene and creates its shading pass (textures, programs) unless done.
    Expected<void> makeVariant(std::size_t v);
    // Takes 'member' (a lamp's settings, or variant 0's own) into v's counts to write out: the
    // fewest of its members'.
    static void narrow(Variant& v, const shading::RenderSettings& member);
    BoothSceneSetup setup_;
    std::vector<Variant> variants_;
    std::vector<std::size_t> lampVariant_;              // by lamp index
    std::vector<shading::RenderSettings> lampSettings_; // by lamp index: its counts
    std::size_t active_ = 0;
    shading::PreparedScene* prepared_ = nullptr; // variants_[active_]'s
    BoothShadingPass* pass_ = nullptr;
    // The light on the GPU now, by its content key (scene::lightKey; none: none yet), and the
    // direct-mode emitter it was made from.
    std::optional<std::uint64_t> heldLight_;
    booth::BoothLight direct_;
    shading::PreparedLight light_;
    // A booth that declares walls (booth::Booth::walls): each lamp's walls, solved at create()
    // (reference::solveWalls, kRealtimeWallPatchM), lampIndex indexing them; empty otherwise.
    std::vector<booth::WallLight> walls_;
    // The encoding on the GPU (SceneState::encoding) and its basis.
    colour::ChannelBasis basis_;
    int encodings_ = 0;
    long warmUpRefreshes_ = 0; // cache refreshes of warmUp()'s draws, not counted
    // Per variant: drawn at least once in this context (its shaders compiled).
    std::vector<bool> drawn_;
    long firstUseDraws_ = 0;
    double lastFirstUseMs_ = 0.0;
    // The light warmUpVariant draws a pass with that is not the active one (light_ stays the
    // active pass's).
    shading::PreparedLight warmLight_;
};

// A uniform emitter with the geometry of 'like', the given luminance and spectrum: what the booth
// shows when the sensed light matches no stored lamp.
booth::BoothLight
uniformEmitter(const booth::BoothLight& like, double luminanceCdM2, const colour::Spectrum& spd);

} // namespace replica::pipeline::render
