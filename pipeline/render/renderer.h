// The renderer interface: scene state in, an absolute-XYZ frame and its display drive values out.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/display/gamut_map.h>
#include <pipeline/scene/scene_state.h>

namespace replica::pipeline::render {

// One rendered frame, rows bottom-up (GL order).
struct RenderedFrame {
    int width = 0;
    int height = 0;
    std::vector<float> xyz; // 4 floats per pixel: X, Y, Z in cd/m^2, then the illuminance on the
                            // panel in lux (what pass 2 takes the flare from)
    std::vector<std::uint8_t> rgba; // 8-bit display counts, 4 per pixel
    display::GamutCounters gamut;   // pixels out of the display's gamut, by class (every frame)
    // The GL framebuffer that holds the display counts (RGBA8, bottom-up) in the renderer's
    // context, until the next render(): what an output on the GPU copies instead of rgba.
    std::uint32_t displayFramebuffer = 0;
};

// What render() copies back from the GPU: reading back costs time, so the loop asks only for what
// it uses (digests need both images; a snapshot needs the display values).
enum class Readback { None, Display, DisplayAndXyz };

// A pixel of a frame: column x, row y counted from the bottom (GL order, as RenderedFrame).
struct FramePixel {
    int x = 0;
    int y = 0;
};

class Renderer
{
public:
    virtual ~Renderer() = default;
    virtual std::string description() const = 0;
    // Renders the frame for this state and reads back what 'readback' asks for into out (resized as
    // needed; the other image is left empty). Returns once the GPU has finished the frame.
    virtual Expected<void> render(const scene::SceneState& state,
                                  RenderedFrame& out,
                                  Readback readback = Readback::DisplayAndXyz) = 0;
    // Pass 1's XYZ of the last frame render() drew, at these pixels only (4 floats each, as
    // RenderedFrame::xyz), without drawing anything: what the error probe compares with the
    // exact reference, a few hundred pixels instead of the whole frame. Call on the thread that
    // renders, between frames.
    virtual Expected<void> readXyzPixels(const std::vector<FramePixel>& pixels,
                                         std::vector<float>& out)
    {
        (void)pixels;
        out.clear();
        return makeError(ErrorCode::Unsupported, "render: this renderer keeps no XYZ frame");
    }
};

} // namespace replica::pipeline::render
