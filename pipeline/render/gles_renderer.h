// The GLES 3.1 renderer: pass 1 computes absolute XYZ per screen pixel (the booth scene,
// booth_scene_pass.h, or the flat patch image, flat_scene_pass.h), pass 2 (display_pass.h) turns
// it into panel counts. Needs a current GLES 3.1 context on the calling thread.
#pragma once

#include <memory>

#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/display_pass.h>
#include <pipeline/render/renderer.h>
#include <pipeline/render/surface_image.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/stand.h>

namespace replica::pipeline::render {

struct GlesRendererSetup {
    int width = 960;
    int height = 600;
    booth::Booth booth; // scene::loadDefaultBooth; the flat image is lit from its ceiling()
    scene::StandModel stand;
    SurfaceImage surface; // the flat renderer's patch image (FlatSceneSetup)
    colour::ChannelBasis basis;
    colour::Observer observer;
    DisplayPassSetup display; // pass 2: the display profile and what the pass does with it
    int lightsU = 8;          // the flat renderer's grid of point lights across the emitter
    int lightsV = 4;
    // When set, pass 1 is the booth-lit surface scene (booth_scene_pass.h) instead of the flat
    // patch image under the uniform grid of lights above.
    std::shared_ptr<BoothScenePass> boothScene;
};

Expected<std::unique_ptr<Renderer>> createGlesRenderer(GlesRendererSetup setup);

} // namespace replica::pipeline::render
