// The booth pass driven by the loop's scene state: the classified lamp picks the booth light (its
// measured luminance image), an unknown light becomes a uniform emitter with the sensed spectrum
// (the paper's direct-sensor mode); the eye comes from the tracker, the panel pose from the tilt
// through the stand's hinge model. With a light-adaptive encoder (basis "adaptive_k6") the surface
// is re-encoded for each new light, synchronously, inside the draw that first sees it, so that
// which frame shows the new encoding follows from the scene states alone (replay stays bit-exact).
// Needs a current GLES 3.1 context for every call.
#pragma once

#include <array>
#include <map>
#include <memory>
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
};

struct BoothSceneSetup {
    booth::Booth booth;             // lights with luminance images (data/booth)
    std::vector<std::string> lamps; // the scene state's lamp names, by lampIndex
    surface::SurfaceScene scene;
    colour::ChannelBasis basis;
    colour::Observer observer;
    scene::StandModel stand;
    shading::RenderSettings settings;
    // Basis "adaptive_k6": when set, 'basis' is the encoder's general basis until the first light
    // with luminance, and every new lamp (or a sensed shape moved by more than reencodeDistance)
    // gets a basis of its own and a re-encoded surface (pipeline/spectral/adaptive_encoding.h).
    std::shared_ptr<const spectral::AdaptiveEncoder> adaptive;
    double reencodeDistance = spectral::kAdaptiveReencodeDistance;
    // The booth dimmer (platform/booth_dimmer.h) for the direct-sensor mode's uniform emitter:
    // the sensed luminance times this. The booth's own lamps come already scaled in 'booth'.
    double luminanceScale = 1.0;
    // Per lamp name: its own lights, specular samples and horizon directions. A lamp not named
    // here, and the direct-sensor mode, draw with 'settings'. Each distinct setting gets a shading
    // pass of its own, built by create(); a lamp change switches to its pass.
    std::map<std::string, LampSettings> perLamp;
};

// The cached diffuse term's tilt is the mean of the last kTiltWindow sensed tilts (the
// accelerometer's 0.02 m/s^2 noise is 0.12 degrees a sample, 0.03 degrees in the mean), re-taken
// when it moves more than kTiltHoldRad: 0.15 degrees, 3.5 standard deviations of the difference
// of two such means, so noise alone almost never recomputes the cache. Holding the diffuse term
// 0.15 degrees off costs at most ΔE00 p95 0.25 at a 5-degree tilt (the ceiling light grazes the
// panel there; the painting's relief) and 0.11 from 20 degrees up, on every shipped scene and
// light (CPU model, booth_cache_test.cpp; docs/rendering.md): about what one sample's noise costs.
constexpr std::size_t kTiltWindow = 16;
constexpr double kTiltHoldRad = 0.15 * 3.14159265358979323846 / 180.0;

class BoothScenePass
{
public:
    static Expected<std::unique_ptr<BoothScenePass>> create(BoothSceneSetup setup);

    // Draws the state's frame into the bound RGBA32F framebuffer (viewport width x height, the
    // whole panel; the surface at its physical size in the middle, black around it; alpha: the
    // illuminance on the panel, lux). The cached diffuse term is drawn at heldTiltRad(), so that
    // sensor noise on the tilt does not recompute it every frame (with settings.cacheSlices = K >
    // 1 a new held tilt shows once its K bands are drawn, K - 1 to 2K - 2 draws later:
    // BoothShadingPass::draw); the specular term at the state's tilt and eye.
    Expected<void> draw(const scene::SceneState& state, int width, int height);

    // The pixels of a width x height frame that can show the surface; draw() writes XYZ (0, 0, 0)
    // everywhere else (render::surfaceRect).
    PixelRect surfaceRect(int width, int height) const;

    // The tilt of the cached diffuse term: the mean of the last kTiltWindow sensed tilts as it
    // was at the last light change or the last time that mean moved more than kTiltHoldRad away
    // from it. A deterministic function of the states drawn so far, so replay renders the same
    // frames.
    double heldTiltRad() const { return heldTiltRad_; }
    // The pass's cache of the eye-independent part (booth_shading_pass.h): how often it was
    // recomputed, and a way to force it (e.g. after the channel encoding changed).
    long cacheRefreshes() const;
    void invalidateCache();
    // BoothShadingPass::setSurroundIlluminance.
    void setSurroundIlluminance(bool on);
    bool surroundIlluminance() const { return pass_->surroundIlluminance(); }

    std::string description() const;

    // Draws every shading pass once (one per distinct lamp setting, each with a lamp that uses
    // it) into a width x height target of its own, so that the shaders' first-use compilation
    // (llvmpipe compiles a program's code at its first draw, 0.7-10 s for the booth pass) happens
    // here, before the loop's first frame, and not at the first switch to each lamp. Give it the
    // frame's size: llvmpipe compiles a variant per texture shape (power-of-two sides or not), so
    // a target of another shape may leave the frame's variant to compile at the switch. Leaves
    // every frame as it would be without (each pass is given its lamp's light again before it
    // draws; booth_warm_up_test.cpp) and cacheRefreshes() as it was. Returns how long it took, ms.
    Expected<double> warmUp(int width, int height);
    // How many shading passes there are (one per distinct setting).
    std::size_t variantCount() const { return variants_.size(); }

    // The basis the surface is encoded in now, and how many times it has been re-encoded (0
    // without an adaptive encoder).
    const colour::ChannelBasis& basis() const { return setup_.basis; }
    int encodings() const { return encodings_; }

private:
    BoothScenePass() = default;
    // Uploads the state's light when it differs from the one on the GPU; 'changed' says so.
    Expected<void> selectLight(const scene::SceneState& state, bool& changed);
    // With an adaptive encoder: a new basis for 'spd' and the palette re-projected onto it, the
    // coefficient textures replaced. A lamp change always re-encodes (unless already encoded for
    // exactly that spectrum); direct-sensor mode only past reencodeDistance. A light the encoder
    // refuses (no luminance, a non-finite band) keeps the encoding it has.
    Expected<void> encodeFor(const colour::Spectrum& spd, bool lampChange);

    // One shading pass per distinct setting (variants_[0]: setup_.settings), each with the scene
    // prepared for its horizon directions; 'encodings' is the encodings_ its channels hold.
    struct Variant {
        shading::RenderSettings settings;
        std::unique_ptr<shading::PreparedScene> prepared;
        std::unique_ptr<BoothShadingPass> pass;
        int encodings = 0;
    };
    // Makes variant v the one drawn, its channels brought up to date.
    Expected<void> useVariant(std::size_t v);

    BoothSceneSetup setup_;
    std::vector<Variant> variants_;
    std::vector<std::size_t> lampVariant_; // by lamp index
    std::size_t active_ = 0;
    shading::PreparedScene* prepared_ = nullptr; // variants_[active_]'s
    BoothShadingPass* pass_ = nullptr;
    // The light on the GPU now: a booth light (by index) or the direct-mode emitter.
    int lightIndex_ = -2;
    colour::Spectrum directSpd_{};
    double directLuminance_ = -1.0;
    booth::BoothLight direct_;
    shading::PreparedLight light_;
    bool encoded_ = false; // encodedFor_ holds the light of the current adaptive basis
    colour::Spectrum encodedFor_{};
    int encodings_ = 0;
    std::array<double, kTiltWindow> tiltWindow_{};
    std::size_t tiltNext_ = 0;
    std::size_t tiltCount_ = 0;
    double heldTiltRad_ = 0.0;
    bool heldValid_ = false;
    long warmUpRefreshes_ = 0; // cache refreshes of warmUp()'s draws, not counted
};

// A uniform emitter with the geometry of 'like', the given luminance and spectrum: what the booth
// shows when the sensed light matches no stored lamp.
booth::BoothLight
uniformEmitter(const booth::BoothLight& like, double luminanceCdM2, const colour::Spectrum& spd);

} // namespace replica::pipeline::render
