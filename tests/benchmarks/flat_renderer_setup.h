// The flat renderer as the display and loop benchmarks draw it.
#pragma once

#include <pipeline/base/data_dir.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/render/surface_image.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/scene_state.h>

namespace replica::bench {

// 960x600 with the default booth, the box basis, the CIE 1931 observer and the ColorChecker's
// patch image at 600x400; the display (pass 2) is the benchmark's.
inline pipeline::render::GlesRendererSetup flatColorCheckerSetup()
{
    pipeline::render::GlesRendererSetup s;
    s.width = 960;
    s.height = 600;
    s.booth = *pipeline::scene::loadDefaultBooth(dataDir().string());
    s.basis = pipeline::colour::boxBasis();
    s.observer = *pipeline::colour::loadCie1931(dataDir());
    s.surface = *pipeline::render::makeColorCheckerSurface(dataDir().string(), s.basis, 600, 400);
    return s;
}

// The state both draw: the booth's first lamp's spectrum at 2200 cd/m^2, the panel at 0.35 rad.
inline pipeline::scene::SceneState flatState(const pipeline::render::GlesRendererSetup& s)
{
    pipeline::scene::SceneState st;
    st.illuminant = s.booth.lights[0].referenceSpectrum;
    st.emitterLuminanceCdM2 = 2200.0;
    st.tiltRad = 0.35;
    return st;
}

} // namespace replica::bench
