// The RGBA32F target the booth pass draws into for tests, the benchmark and 'replica render', read
// back as an XyzFrame, and one frame of the GPU path into a fresh one.
#pragma once

#include <memory>

#include <GLES3/gl31.h>

#include <pipeline/base/expected.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/shading/frame.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/view.h>

namespace replica::pipeline::render {

class BoothShadingPass;

// An RGBA32F render target with read-back into an XyzFrame (rows top-down, like the CPU model):
// what the tests and the benchmark render into.
class XyzTarget
{
public:
    static Expected<std::unique_ptr<XyzTarget>> create(int width, int height);
    ~XyzTarget();
    XyzTarget(const XyzTarget&) = delete;
    XyzTarget& operator=(const XyzTarget&) = delete;

    void bind() const;
    // Waits for the frame and reads it back. nonFinite counts components that are NaN or Inf (the
    // shader must never produce one); whiteY/whiteXyz are filled from 'light' at the view's panel
    // centre as shading::renderRealtime does with point lights. With flareRho > 0 (the pass
    // subtracted the screen's flare) flareClamped counts the components the subtraction took to
    // zero, as shading::subtractFlare counts them: 0 where the flare, light.white * flareRho *
    // E_geo / pi with E_geo read from alpha, is positive.
    shading::XyzFrame read(const shading::PreparedLight& light,
                           const shading::View& view,
                           double flareRho = 0.0) const;
    int width() const { return width_; }
    int height() const { return height_; }

private:
    XyzTarget() = default;
    int width_ = 0;
    int height_ = 0;
    GlTexture texture_;
    GlFramebuffer fbo_;
};

// One frame of the GPU path into a fresh target: for tests, the benchmark and 'replica render'.
// The frame carries what shading::renderRealtime reports: whiteY from areas or points as the
// pass's settings say, the pixels with the eye at or behind the surface (exit 3 in 'replica
// render') and the flare's clamped components.
Expected<shading::XyzFrame> renderBoothFrame(BoothShadingPass& pass,
                                             const shading::PreparedLight& light,
                                             const shading::View& view);

} // namespace replica::pipeline::render
