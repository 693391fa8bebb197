// The GLES 3.1 renderer: pass 1 computes absolute XYZ per screen pixel and the illuminance on the
// panel (the booth scene, booth_scene_pass.h), pass 2 (display_pass.h) turns it into panel counts.
// Needs a current GLES 3.1 context on the calling thread.
#pragma once

#include <memory>

#include <pipeline/colour/xyz.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/display_pass.h>
#include <pipeline/render/renderer.h>
#include <pipeline/scene/stand.h>

namespace replica::pipeline::render {

struct GlesRendererSetup {
    int width = 960;
    int height = 600;
    scene::StandModel stand;
    colour::Observer observer; // the booth light's colour, for pass 2's flare
    DisplayPassSetup display;  // pass 2: the display profile and what the pass does with it
    // Pass 1: the booth-lit surface scene (booth_scene_pass.h); required.
    std::shared_ptr<BoothScenePass> boothScene;
};

Expected<std::unique_ptr<Renderer>> createGlesRenderer(GlesRendererSetup setup);

} // namespace replica::pipeline::render
