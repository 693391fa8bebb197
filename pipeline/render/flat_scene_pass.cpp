// Pass 1 of the flat renderer.
#include <algorithm>
#include <array>

#include <GLES3/gl31.h>
#include <fmt/format.h>
#include <glm/vec3.hpp>

#include <pipeline/render/flat_scene_pass.h>
#include <pipeline/render/gl_program.h>

namespace replica::pipeline::render {
namespace {

// Paper eq. (1) over point lights, eq. (2) per channel, summed into absolute XYZ (cd/m^2).
const char* const kFlatXyzShader = R"(#version 310 es
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

} // namespace

Expected<std::unique_ptr<FlatScenePass>> FlatScenePass::create(FlatSceneSetup setup)
{
    std::unique_ptr<FlatScenePass> pass(new FlatScenePass());
    pass->setup_ = std::move(setup);
    if (auto ok = pass->init(); !ok) {
        return tl::unexpected(ok.error());
    }
    return pass;
}

Expected<void> FlatScenePass::init()
{
    auto xyz = linkProgram(kFullscreenVertexShader, kFlatXyzShader, "XYZ");
    if (!xyz) {
        return tl::unexpected(xyz.error());
    }
    program_ = std::move(*xyz);
    vao_ = GlVertexArray::make();
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
    return {};
}

std::string FlatScenePass::description() const
{
    return fmt::format("gles-diffuse ({}x{} point lights, basis {})", setup_.lightsU,
                       setup_.lightsV, setup_.basis.name);
}

std::vector<float> FlatScenePass::lights(const scene::SceneState& state) const
{
    const auto grid = scene::uniformGridLights(setup_.booth.ceiling(), state.emitterLuminanceCdM2,
                                               setup_.lightsU, setup_.lightsV);
    const int count = static_cast<int>(std::min<std::size_t>(grid.size(), kMaxLights));
    std::vector<float> packed;
    packed.reserve(static_cast<std::size_t>(count) * 4);
    for (int i = 0; i < count; ++i) {
        const auto& l = grid[static_cast<std::size_t>(i)];
        packed.insert(packed.end(),
                      {static_cast<float>(l.position.x), static_cast<float>(l.position.y),
                       static_cast<float>(l.position.z), static_cast<float>(l.intensityCd)});
    }
    return packed;
}

void FlatScenePass::draw(const scene::SceneState& state,
                         const scene::PanelPose& pose,
                         const std::vector<float>& lights) const
{
    const colour::ChannelToXyz m =
            colour::channelToXyz(setup_.basis, setup_.observer, state.illuminant);
    const auto count = static_cast<GLsizei>(lights.size() / 4);
    const GLuint p = program_.get();

    glBindVertexArray(vao_.get());
    glUseProgram(p);
    setUniform3(p, "uPanelOrigin", pose.cornerM());
    setUniform3(p, "uPanelRight", pose.rightEdgeM());
    setUniform3(p, "uPanelUp", pose.upEdgeM());
    setUniform3(p, "uPanelNormal", pose.normal);
    setUniform3(p, "uLightNormal", setup_.booth.ceiling().normal());
    glUniform1i(glGetUniformLocation(p, "uLightCount"), count);
    if (count > 0) {
        glUniform4fv(glGetUniformLocation(p, "uLights"), count, lights.data());
    }
    std::array<float, colour::kChannels * 3> mf{};
    for (std::size_t k = 0; k < colour::kChannels; ++k) {
        for (int c = 0; c < 3; ++c) {
            mf[k * 3 + static_cast<std::size_t>(c)] = static_cast<float>(m[k][c]);
        }
    }
    glUniform3fv(glGetUniformLocation(p, "uChannelXyz"), static_cast<GLsizei>(colour::kChannels),
                 mf.data());
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, coeffA_.get());
    glUniform1i(glGetUniformLocation(p, "uCoeffA"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, coeffB_.get());
    glUniform1i(glGetUniformLocation(p, "uCoeffB"), 1);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

} // namespace replica::pipeline::render
