// The booth pass driven by the loop's scene state: the classified lamp picks the booth light (its
// measured luminance image), an unknown light becomes a uniform emitter with the sensed spectrum
// (the paper's direct-sensor mode); the eye comes from the tracker, the panel pose from the tilt
// through the stand's hinge model. With a light-adaptive encoder (basis "adaptive_k6") the surface
// is re-encoded for each new light, synchronously, inside the draw that first sees it, so that
// which frame shows the new encoding follows from the scene states alone (replay stays bit-exact).
// Needs a current GLES 3.1 context for every call.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <pipeline/booth/booth_model.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/scene_state.h>
#include <pipeline/spectral/adaptive_encoding.h>

namespace replica::pipeline::render {

struct BoothSceneSetup {
    booth::BoothModel booth;        // lights with luminance images (data/booth)
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
};

class BoothScenePass
{
public:
    static Expected<std::unique_ptr<BoothScenePass>> create(BoothSceneSetup setup);

    // Draws the state's frame into the bound RGBA32F framebuffer (viewport width x height, the
    // whole panel; the surface at its physical size in the middle, black around it).
    Expected<void> draw(const scene::SceneState& state, int width, int height);

    std::string description() const;

    // The basis the surface is encoded in now, and how many times it has been re-encoded (0
    // without an adaptive encoder).
    const colour::ChannelBasis& basis() const { return setup_.basis; }
    int encodings() const { return encodings_; }

private:
    BoothScenePass() = default;
    Expected<void> selectLight(const scene::SceneState& state);
    // With an adaptive encoder: a new basis for 'spd' and the palette re-projected onto it, the
    // coefficient textures replaced. A lamp change always re-encodes (unless already encoded for
    // exactly that spectrum); direct-sensor mode only past reencodeDistance. A light the encoder
    // refuses (no luminance, a non-finite band) keeps the encoding it has.
    Expected<void> encodeFor(const colour::Spectrum& spd, bool lampChange);

    BoothSceneSetup setup_;
    shading::PreparedScene prepared_;
    std::unique_ptr<BoothShadingPass> pass_;
    // The light on the GPU now: a booth light (by index) or the direct-mode emitter.
    int lightIndex_ = -2;
    colour::Spectrum directSpd_{};
    double directLuminance_ = -1.0;
    booth::BoothLight direct_;
    shading::PreparedLight light_;
    bool encoded_ = false; // encodedFor_ holds the light of the current adaptive basis
    colour::Spectrum encodedFor_{};
    int encodings_ = 0;
};

// A uniform emitter with the geometry of 'like', the given luminance and spectrum: what the booth
// shows when the sensed light matches no stored lamp.
booth::BoothLight
uniformEmitter(const booth::BoothLight& like, double luminanceCdM2, const colour::Spectrum& spd);

} // namespace replica::pipeline::render
