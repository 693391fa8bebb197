// The GLES 3.1 renderer: pass 1 (the booth scene) into an RGBA32F XYZ target, pass 2 (the display
// pass) into panel counts, and the read-back.
#include <string>

#include <GLES3/gl31.h>
#include <fmt/format.h>

#include <pipeline/render/gl_handles.h>
#include <pipeline/render/gl_program.h>
#include <pipeline/render/gles_renderer.h>

namespace replica::pipeline::render {
namespace {

class GlesRenderer final : public Renderer
{
public:
    explicit GlesRenderer(GlesRendererSetup setup) : setup_(std::move(setup)) {}
    ~GlesRenderer() override = default;
    GlesRenderer(const GlesRenderer&) = delete;
    GlesRenderer& operator=(const GlesRenderer&) = delete;

    Expected<void> init()
    {
        if (auto display = displayPass_.init(setup_.display, setup_.width, setup_.height);
            !display) {
            return tl::unexpected(display.error());
        }
        vao_ = GlVertexArray::make();
        // E_geo around the surface only where the display pass reads it.
        setup_.boothScene->setSurroundIlluminance(!displayPass_.surroundConstant());
        xyzTarget_ = texture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, setup_.width, setup_.height, nullptr);
        fbo_ = GlFramebuffer::make();
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                               xyzTarget_.get(), 0);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            return makeError(ErrorCode::Unsupported,
                             "render: the RGBA32F XYZ target is not renderable on this GL (float "
                             "colour buffers need GLES 3.2 or EXT_color_buffer_float)");
        }
        if (GLenum err = glGetError(); err != GL_NO_ERROR) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("render: GL error 0x{:04x} while setting up", err));
        }
        return {};
    }

    std::string description() const override { return setup_.boothScene->description(); }

    Expected<void>
    render(const scene::SceneState& state, RenderedFrame& out, Readback readback) override
    {
        const int w = setup_.width;
        const int h = setup_.height;
        glViewport(0, 0, w, h);

        // Pass 1: absolute XYZ, and the illuminance on the panel (lux) in alpha from the booth
        // model's lights, what pass 2 takes the flare from.
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
        if (auto ok = setup_.boothScene->draw(state, w, h); !ok) {
            return ok;
        }
        glViewport(0, 0, w, h);
        glBindVertexArray(vao_.get());

        // Pass 2: panel counts (display_pass.cpp).
        DisplayPassFrame df;
        df.pose = scene::panelPose(setup_.stand, state.tiltRad);
        df.eyeM = state.eyeBoothM;
        df.blackOutside = setup_.boothScene->surfaceRect(w, h);
        const colour::Xyz lightXyz = colour::spectrumToXyz(setup_.observer, state.illuminant);
        df.lightXyzUnitY = lightXyz.y > 0.0 ? lightXyz / lightXyz.y : glm::dvec3(0.0);
        auto gamut = displayPass_.draw(xyzTarget_.get(), df);
        if (!gamut) {
            return tl::unexpected(gamut.error());
        }
        out.gamut = *gamut;

        // Read back what the caller uses.
        out.width = w;
        out.height = h;
        out.displayFramebuffer = displayPass_.framebuffer();
        const auto pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        if (readback == Readback::DisplayAndXyz) {
            out.xyz.resize(pixels * 4);
            glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
            glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, out.xyz.data());
        } else {
            out.xyz.clear();
        }
        if (readback != Readback::None) {
            out.rgba.resize(pixels * 4);
            glBindFramebuffer(GL_FRAMEBUFFER, displayPass_.framebuffer());
            glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, out.rgba.data());
        } else {
            out.rgba.clear();
            glFinish(); // keep the frame in step with its tick even when nothing is read
        }
        if (GLenum err = glGetError(); err != GL_NO_ERROR) {
            return makeError(
                    ErrorCode::DeviceFailure,
                    fmt::format("render: GL error 0x{:04x} in frame {}", err, state.frameIndex));
        }
        return {};
    }

    Expected<void> readXyzPixels(const std::vector<FramePixel>& pixels,
                                 std::vector<float>& out) override
    {
        out.assign(pixels.size() * 4, 0.0f);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
        for (std::size_t k = 0; k < pixels.size(); ++k) {
            const auto& p = pixels[k];
            if (p.x < 0 || p.y < 0 || p.x >= setup_.width || p.y >= setup_.height) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("render: pixel ({}, {}) is outside the {}x{} frame",
                                             p.x, p.y, setup_.width, setup_.height));
            }
            glReadPixels(p.x, p.y, 1, 1, GL_RGBA, GL_FLOAT, out.data() + 4 * k);
        }
        if (GLenum err = glGetError(); err != GL_NO_ERROR) {
            return makeError(ErrorCode::DeviceFailure,
                             fmt::format("render: GL error 0x{:04x} reading XYZ pixels", err));
        }
        return {};
    }

private:
    GlesRendererSetup setup_;
    GlVertexArray vao_;
    GlTexture xyzTarget_;
    GlFramebuffer fbo_;
    DisplayPass displayPass_;
};

} // namespace

Expected<std::unique_ptr<Renderer>> createGlesRenderer(GlesRendererSetup setup)
{
    if (!setup.boothScene) {
        return makeError(ErrorCode::InvalidArgument,
                         "the renderer needs its pass 1, the booth scene pass");
    }
    auto r = std::make_unique<GlesRenderer>(std::move(setup));
    if (auto ok = r->init(); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::unique_ptr<Renderer>(std::move(r));
}

} // namespace replica::pipeline::render
