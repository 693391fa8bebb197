// The renderer's second pass: absolute XYZ (cd/m^2) per pixel -> panel counts through a display
// profile's inverse model, with front-surface flare subtraction and viewing-angle compensation per
// pixel, hue-keeping gamut mapping, ordered dither to the panel's bit depth, an optional
// false-colour overlay of out-of-gamut pixels, and a GPU count of those pixels per frame. Needs a
// current GLES 3.1 context; the maths is pipeline/display's (display_pass_params.h mirrors
// display_inverse.h).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <GLES3/gl31.h>
#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_model.h>
#include <pipeline/display/display_pass_params.h>
#include <pipeline/display/gamut_map.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/render/pixel_rect.h>
#include <pipeline/scene/stand.h>

namespace replica::pipeline::render {

enum class InverseMethod {
    Analytic, // M^-1, gamut mapping, per-channel inverse tone LUT (1-D, cube-root domain)
    Lut3d,    // a 33^3 lattice of the analytic path's counts, tetrahedral interpolation
};

struct DisplayPassSetup {
    display::DisplayModel model; // the profile (or the nominal model under --uncalibrated)
    display::GamutMode gamut = display::GamutMode::HueKeeping;
    InverseMethod method = InverseMethod::Analytic;
    int lut3dSize = 33;
    bool viewingCompensation = true; // from the profile's table and the tracked eye; off: on-axis
    // The gain is read from the table resampled every half degree (display::kViewingGridStepDeg)
    // with the sampler's linear filter where the GL filters float textures (GL_OES_texture_float_
    // linear): the same function as the rows to float rounding when the rows lie on the half
    // degrees, 4 % fewer instructions in the painting's frame on llvmpipe; without the extension
    // from the rows themselves.
    bool flareSubtraction = true; // rho_d E / pi per pixel; never for a lit-booth profile
    bool falseColour = false;     // field-staff overlay: out-of-gamut pixels striped in colour
};

// What changes per frame. The flare's illuminance on the panel (lux) is the XYZ texture's alpha,
// where pass 1 wrote it.
struct DisplayPassFrame {
    scene::PanelPose pose;
    glm::dvec3 eyeM{0.0};
    glm::dvec3 lightXyzUnitY{0.0}; // the booth light's colour, Y = 1
    // When set, pass 1 wrote XYZ (0, 0, 0) outside this rectangle (the black panel around a booth
    // surface). There, whatever the flare and the eye, every pixel is below black and gets the
    // counts of XYZ 0; when those counts survive the dither unchanged (DisplayPass::
    // surroundConstant) the pass clears the surround to them and shades only the rectangle: the
    // same pixels and gamut counts, for the surface's share of the work. Unset: the whole frame.
    std::optional<PixelRect> blackOutside;
};

class DisplayPass
{
public:
    DisplayPass() = default;
    ~DisplayPass();
    DisplayPass(const DisplayPass&) = delete;
    DisplayPass& operator=(const DisplayPass&) = delete;

    // Fails when the profile does not validate, is not 8-bit (the output target in this build), or
    // the GL lacks what the pass needs.
    Expected<void> init(const DisplayPassSetup& setup, int width, int height);
    // Whether init found the viewing gain filtered (compensation on and the extension it needs).
    bool viewingFiltered() const { return static_cast<bool>(viewingGrid_); }
    // Reads xyzTexture (RGBA32F, texelFetch), draws into framebuffer(), counts the gamut classes.
    Expected<display::GamutCounters> draw(GLuint xyzTexture, const DisplayPassFrame& frame);
    // The RGBA8 display target (counts / 255; alpha 1).
    GLuint framebuffer() const { return fbo_.get(); }
    // Whether a frame's black surround can be cleared instead of shaded (see blackOutside): the
    // profile has a black above 0 (so XYZ 0 minus any flare is below it), the gamut mapping keeps
    // hue (clipping would map each pixel's flare-lowered XYZ differently), no false colour, and
    // the counts of XYZ 0 are the same after every entry of the dither matrix.
    bool surroundConstant() const { return surroundConstant_; }

private:
    // The display program for the profile's parameters ('filtered': the viewing gain through the
    // sampler) and the gamut count's compute program.
    Expected<void> compilePrograms(const display::DisplayPassParams& params, bool filtered);
    // The 3-D LUT texture (a 2^3 dummy on the analytic path); its lattice and scale.
    std::vector<float> uploadLut3d(const display::DisplayInverse& inverse,
                                   glm::dvec3& latticeScale);
    int lut3dSize() const;
    // surroundConstant_ and surroundRgba_: what a pixel below black is driven to.
    void findSurround(const display::DisplayPassParams& params, const std::vector<float>& lattice);
    // The gamut counts' buffer and the RGBA8 + R8 framebuffer.
    Expected<void> makeTargets();
    void setConstantUniforms(const display::DisplayPassParams& params,
                             const glm::dvec3& latticeScale);
    // The class image's counts (in gamut, chroma, over peak, below black) over 'rect', on the GPU.
    Expected<std::array<GLuint, 4>> countClasses(const PixelRect& rect) const;

    DisplayPassSetup setup_;
    int width_ = 0;
    int height_ = 0;
    GlProgram program_;
    GlProgram countProgram_;
    GlFramebuffer fbo_;
    GlTexture rgbaTarget_;
    GlTexture classTarget_;
    GlTexture toneLut_;
    GlTexture viewingGrid_; // none unless the gain is filtered (compensation on and the GL filters
                            // floats)
    GlTexture lut3d_;
    GlBuffer counts_; // SSBO of 4 uints, one per gamut class
    float flarePerLux_ = 0.0f;
    bool surroundConstant_ = false;
    std::array<float, 4> surroundRgba_{}; // the surround's output, as the shader writes it
    glm::dvec3 white_{0.0};
};

} // namespace replica::pipeline::render
