// GLES 3.1 implementation of the renderer.
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include <GLES3/gl31.h>
#include <fmt/format.h>
#include <glm/matrix.hpp>

#include <pipeline/render/gl_handles.h>
#include <pipeline/render/gl_program.h>
#include <pipeline/render/gles_renderer.h>

namespace replica::pipeline::render {
namespace {

constexpr int kMaxLights = 256;

// Paper eq. (1) over point lights, eq. (2) per channel, summed into absolute XYZ (cd/m^2).
const char* const kXyzShader = R"(#version 310 es
precision highp float;
precision highp int;
in vec2 vUv;
out vec4 outXyz;
uniform highp sampler2D uCoeffA;   // channels 0..2
uniform highp sampler2D uCoeffB;   // channels 3..5
uniform vec3 uPanelOrigin;
uniform vec3 uPanelRight;
uniform vec3 uPanelUp;
uniform vec3 uPanelNormal;
uniform vec3 uLightNormal;
uniform int uLightCount;
uniform vec4 uLights[256];         // xyz: position (m); w: L * a (cd)
uniform vec3 uChannelXyz[6];
const float kPi = 3.14159265358979;
void main() {
    vec3 p = uPanelOrigin + vUv.x * uPanelRight + vUv.y * uPanelUp;
    float e = 0.0;
    for (int i = 0; i < uLightCount; ++i) {
        vec3 d = uLights[i].xyz - p;
        // Guard 1/d^2: a light touching the surface contributes a bounded amount.
        float d2 = max(dot(d, d), 1e-6);
        vec3 dir = d * inversesqrt(d2);
        float cosSurface = max(dot(uPanelNormal, dir), 0.0);
        float cosLight = max(dot(uLightNormal, -dir), 0.0);
        e += uLights[i].w * cosSurface * cosLight / d2;
    }
    vec3 a = texture(uCoeffA, vUv).rgb;
    vec3 b = texture(uCoeffB, vUv).rgb;
    vec3 xyz = a.r * uChannelXyz[0] + a.g * uChannelXyz[1] + a.b * uChannelXyz[2]
             + b.r * uChannelXyz[3] + b.g * uChannelXyz[4] + b.b * uChannelXyz[5];
    outXyz = vec4(xyz * (e / kPi), 1.0);
}
)";

glm::vec3 toFloat(const glm::dvec3& v)
{
    return glm::vec3(static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z));
}

class GlesRenderer final : public Renderer
{
public:
    explicit GlesRenderer(GlesRendererSetup setup) : setup_(std::move(setup)) {}
    ~GlesRenderer() override = default;
    GlesRenderer(const GlesRenderer&) = delete;
    GlesRenderer& operator=(const GlesRenderer&) = delete;

    Expected<void> init()
    {
        auto xyz = linkProgram(kFullscreenVertexShader, kXyzShader, "XYZ");
        if (!xyz) {
            return tl::unexpected(xyz.error());
        }
        xyzProgram_ = std::move(*xyz);
        if (auto display = displayPass_.init(setup_.display, setup_.width, setup_.height);
            !display) {
            return tl::unexpected(display.error());
        }
        vao_ = GlVertexArray::make();
        if (setup_.boothScene) {
            setup_.boothScene->setSurroundIlluminance(setup_.surroundIlluminance ||
                                                      !displayPass_.surroundConstant());
        }

        const auto& s = setup_.surface;
        const auto texels = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
        if (s.width <= 0 || s.height <= 0 || s.coeffs.size() != texels * colour::kChannels) {
            return makeError(ErrorCode::InvalidArgument, "render: the surface image is empty or "
                                                         "has the wrong number of coefficients");
        }
        std::vector<float> a(texels * 3);
        std::vector<float> b(texels * 3);
        for (std::size_t i = 0; i < texels; ++i) {
            for (std::size_t c = 0; c < 3; ++c) {
                a[i * 3 + c] = s.coeffs[i * colour::kChannels + c];
                b[i * 3 + c] = s.coeffs[i * colour::kChannels + 3 + c];
            }
        }
        coeffA_ = texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, a.data());
        coeffB_ = texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, b.data());
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

    std::string description() const override
    {
        if (setup_.boothScene) {
            return setup_.boothScene->description();
        }
        return fmt::format("gles-diffuse ({}x{} point lights, basis {})", setup_.lightsU,
                           setup_.lightsV, setup_.basis.name);
    }

    Expected<void>
    render(const scene::SceneState& state, RenderedFrame& out, Readback readback) override
    {
        const int w = setup_.width;
        const int h = setup_.height;
        // The panel pose and, for the flat image, the uniform grid of lights: its pass 1 and
        // pass 2's flare estimate use them. The booth pass writes the illuminance on the panel
        // itself (the XYZ target's alpha), from the booth model's lights.
        const scene::PanelPose pose = scene::panelPose(setup_.stand, state.tiltRad);
        std::vector<float> packed;
        int count = 0;
        if (!setup_.boothScene) {
            const auto lights =
                    scene::uniformGridLights(setup_.booth.ceiling(), state.emitterLuminanceCdM2,
                                             setup_.lightsU, setup_.lightsV);
            count = static_cast<int>(std::min<std::size_t>(lights.size(), kMaxLights));
            packed.reserve(static_cast<std::size_t>(count) * 4);
            for (int i = 0; i < count; ++i) {
                const auto& l = lights[static_cast<std::size_t>(i)];
                packed.insert(packed.end(),
                              {static_cast<float>(l.position.x), static_cast<float>(l.position.y),
                               static_cast<float>(l.position.z),
                               static_cast<float>(l.intensityCd)});
            }
        }
        glViewport(0, 0, w, h);

        // Pass 1: absolute XYZ.
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
        if (setup_.boothScene) {
            if (auto ok = setup_.boothScene->draw(state, w, h); !ok) {
                return ok;
            }
        } else {
            drawFlatXyz(state, pose, packed, count);
        }
        glViewport(0, 0, w, h);
        glBindVertexArray(vao_.get());

        // Pass 2: panel counts (display_pass.cpp).
        DisplayPassFrame df;
        df.pose = pose;
        df.eyeM = state.eyeBoothM;
        df.lights = &packed;
        df.lightCount = count;
        df.lightNormal = setup_.booth.ceiling().normal();
        df.illuminanceInAlpha = setup_.boothScene != nullptr;
        if (setup_.boothScene) {
            df.blackOutside = setup_.boothScene->surfaceRect(w, h);
        }
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

private:
    // Pass 1 of the flat patch image: eq. (1) over a uniform grid of lights, eq. (2).
    void drawFlatXyz(const scene::SceneState& state,
                     const scene::PanelPose& pose,
                     const std::vector<float>& packed,
                     int count)
    {
        const colour::ChannelToXyz m =
                colour::channelToXyz(setup_.basis, setup_.observer, state.illuminant);

        glBindVertexArray(vao_.get());

        glUseProgram(xyzProgram_.get());
        setVec3(xyzProgram_.get(), "uPanelOrigin", pose.cornerM());
        setVec3(xyzProgram_.get(), "uPanelRight", pose.rightEdgeM());
        setVec3(xyzProgram_.get(), "uPanelUp", pose.upEdgeM());
        setVec3(xyzProgram_.get(), "uPanelNormal", pose.normal);
        setVec3(xyzProgram_.get(), "uLightNormal", setup_.booth.ceiling().normal());
        glUniform1i(glGetUniformLocation(xyzProgram_.get(), "uLightCount"), count);
        if (count > 0) {
            glUniform4fv(glGetUniformLocation(xyzProgram_.get(), "uLights"), count, packed.data());
        }
        std::array<float, colour::kChannels * 3> mf{};
        for (std::size_t k = 0; k < colour::kChannels; ++k) {
            for (int c = 0; c < 3; ++c) {
                mf[k * 3 + static_cast<std::size_t>(c)] = static_cast<float>(m[k][c]);
            }
        }
        glUniform3fv(glGetUniformLocation(xyzProgram_.get(), "uChannelXyz"),
                     static_cast<GLsizei>(colour::kChannels), mf.data());
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, coeffA_.get());
        glUniform1i(glGetUniformLocation(xyzProgram_.get(), "uCoeffA"), 0);
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, coeffB_.get());
        glUniform1i(glGetUniformLocation(xyzProgram_.get(), "uCoeffB"), 1);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }

    static void setVec3(GLuint program, const char* name, const glm::dvec3& v)
    {
        const glm::vec3 f = toFloat(v);
        glUniform3f(glGetUniformLocation(program, name), f.x, f.y, f.z);
    }

    GlesRendererSetup setup_;
    GlProgram xyzProgram_;
    GlVertexArray vao_;
    GlTexture coeffA_;
    GlTexture coeffB_;
    GlTexture xyzTarget_;
    GlFramebuffer fbo_;
    DisplayPass displayPass_;
};

} // namespace

Expected<std::unique_ptr<Renderer>> createGlesRenderer(GlesRendererSetup setup)
{
    if (setup.booth.lights.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "the renderer needs a booth with at least one light (its ceiling)");
    }
    auto r = std::make_unique<GlesRenderer>(std::move(setup));
    if (auto ok = r->init(); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::unique_ptr<Renderer>(std::move(r));
}

} // namespace replica::pipeline::render
