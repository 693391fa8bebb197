// The booth pass driven by the loop's scene state: the classified lamp picks the booth light (its
// measured luminance image), an unknown light becomes a uniform emitter with the sensed spectrum
// (the paper's direct-sensor mode); the eye comes from the tracker, the panel pose from the tilt
// through the stand's hinge model. Needs a current GLES 3.1 context for every call.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <pipeline/booth/booth_model.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/scene_state.h>

namespace replica::pipeline::render {

struct BoothSceneSetup {
    booth::BoothModel booth;        // lights with luminance images (data/booth)
    std::vector<std::string> lamps; // the scene state's lamp names, by lampIndex
    surface::SurfaceScene scene;
    colour::ChannelBasis basis;
    colour::Observer observer;
    scene::StandModel stand;
    shading::RenderSettings settings;
};

class BoothScenePass
{
public:
    static Expected<std::unique_ptr<BoothScenePass>> create(BoothSceneSetup setup);

    // Draws the state's frame into the bound RGBA32F framebuffer (viewport width x height, the
    // whole panel; the surface at its physical size in the middle, black around it).
    Expected<void> draw(const scene::SceneState& state, int width, int height);

    std::string description() const;

private:
    BoothScenePass() = default;
    Expected<void> selectLight(const scene::SceneState& state);

    BoothSceneSetup setup_;
    shading::PreparedScene prepared_;
    std::unique_ptr<BoothShadingPass> pass_;
    // The light on the GPU now: a booth light (by index) or the direct-mode emitter.
    int lightIndex_ = -2;
    colour::Spectrum directSpd_{};
    double directLuminance_ = -1.0;
    booth::BoothLight direct_;
    shading::PreparedLight light_;
};

// A uniform emitter with the geometry of 'like', the given luminance and spectrum: what the booth
// shows when the sensed light matches no stored lamp.
booth::BoothLight
uniformEmitter(const booth::BoothLight& like, double luminanceCdM2, const colour::Spectrum& spd);

} // namespace replica::pipeline::render
