// Pass 1 of the flat renderer: a patch image (SurfaceImage, K = 6 channel coefficients a texel in
// a fixed basis) flat on the panel under a uniform grid of point lights over the booth's ceiling:
// paper eq. (1) per pixel over the grid, eq. (2) per channel, into absolute XYZ (cd/m^2). The
// booth renderer's pass 1 is BoothScenePass. Needs a current GLES 3.1 context for every call.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/render/surface_image.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/scene_state.h>
#include <pipeline/scene/stand.h>

namespace replica::pipeline::render {

struct FlatSceneSetup {
    SurfaceImage surface;
    booth::Booth booth; // the flat image is lit from its ceiling()
    colour::ChannelBasis basis;
    colour::Observer observer;
    int lightsU = 8; // point lights across the ceiling
    int lightsV = 4;
};

class FlatScenePass
{
public:
    // The most lights of the grid the shader takes.
    static constexpr int kMaxLights = 256;

    // Uploads the image's coefficients; fails with one line on an empty or malformed image.
    static Expected<std::unique_ptr<FlatScenePass>> create(FlatSceneSetup setup);

    // The state's grid of lights, each as position (m) and intensity (cd): what draw() sums and
    // what pass 2 estimates the flare from (DisplayPassFrame::lights).
    std::vector<float> lights(const scene::SceneState& state) const;
    // Draws the state's frame at 'pose' into the bound RGBA32F framebuffer (the viewport; alpha 1)
    // from 'lights' (lights()).
    void draw(const scene::SceneState& state,
              const scene::PanelPose& pose,
              const std::vector<float>& lights) const;

    std::string description() const;
    const booth::Booth& booth() const { return setup_.booth; }

private:
    FlatScenePass() = default;
    Expected<void> init();

    FlatSceneSetup setup_;
    GlProgram program_;
    GlVertexArray vao_;
    GlTexture coeffA_;
    GlTexture coeffB_;
};

} // namespace replica::pipeline::render
