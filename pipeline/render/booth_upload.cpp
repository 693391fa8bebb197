// The booth pass's upload helpers: textures for the scene's channels, normals and horizons, the
// grids' targets, and each mode's program source (the BOOTH_* defines before the GLSL files).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>
#include <glm/gtc/packing.hpp>

#include <pipeline/render/booth_shaders.h>
#include <pipeline/render/booth_upload.h>

namespace replica::pipeline::render::booth_upload {

// Float textures are read with texelFetch only: nearest sampling keeps them complete without the
// float-filtering extension, and the shader does its own (border-0) bilinear where the model does.
void nearest(GLenum target)
{
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

// A grid's target: one R32F texel per node (made on 'unit', so that creating it binds over no
// other input) and a framebuffer that draws into it.
Expected<void> nodeTarget(shading::GridNodes nodes,
                          GLint unit,
                          const char* grid,
                          GlTexture& texture,
                          GlFramebuffer& fbo,
                          bool twoValues)
{
    glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
    texture = twoValues ? texture2d(GL_RG32F, GL_RG, GL_FLOAT, nodes.x, nodes.y, nullptr)
                        : texture2d(GL_R32F, GL_RED, GL_FLOAT, nodes.x, nodes.y, nullptr);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
    fbo = GlFramebuffer::make();
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture.get(), 0);
    const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!complete) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("render: the booth pass's {1} {0} grid is not renderable "
                                     "on this GL; run with a {0} grid of 0 (per pixel)",
                                     grid, twoValues ? "RG32F" : "R32F"));
    }
    return {};
}

// The horizon map as a 2-D array texture: directions [8j, 8j + 8) as half floats in layer j of an
// RGBA32UI array (packHalf2x16's layout: direction 2i in the low 16 bits of word i). 'dirs' 0: one
// empty texel.
GlTexture horizonTexture(const surface::HorizonMap& map, int dirs)
{
    constexpr int kPerLayer = 8;
    const int layers = std::max((dirs + kPerLayer - 1) / kPerLayer, 1);
    const int w = dirs > 0 ? map.width : 1;
    const int h = dirs > 0 ? map.height : 1;
    const auto texels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    const auto k = static_cast<std::size_t>(dirs);
    std::vector<std::uint32_t> words(texels * 4 * static_cast<std::size_t>(layers), 0u);
    for (std::size_t i = 0; i < texels && k > 0; ++i) {
        for (std::size_t d = 0; d < k; ++d) {
            const std::size_t word = ((d / 8) * texels + i) * 4 + (d % 8) / 2;
            words[word] |= static_cast<std::uint32_t>(glm::packHalf1x16(map.sinBeta[i * k + d]))
                           << (d % 2 == 0 ? 0 : 16);
        }
    }
    GlTexture tex = GlTexture::make();
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex.get());
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA32UI, w, h, layers);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, w, h, layers, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                    words.data());
    nearest(GL_TEXTURE_2D_ARRAY);
    return tex;
}

glm::vec3 f3(const glm::dvec3& v)
{
    return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

// 2 x the specular mip level bias for the GL pass's exact level (the nearest level and a bias of
// whole half levels; within kMaxSpecularLodBias, 4^bias keeps the shader's clamped ratio, 1e-20
// to 1e30, a normal float), else nothing: the GL pass renders no other setting.
std::optional<int> exactLevelTwiceBias(const shading::RenderSettings& s)
{
    const double twice = 2.0 * s.specularLodBias;
    if (!s.specularNearestLevel || !(std::abs(twice) <= 2.0 * shading::kMaxSpecularLodBias) ||
        twice != std::round(twice)) {
        return std::nullopt;
    }
    return static_cast<int>(twice);
}

int wardModelIndex(brdf::WardModel m)
{
    switch (m) {
    case brdf::WardModel::Ward1992:
        return 0;
    case brdf::WardModel::WardDur:
        return 1;
    case brdf::WardModel::WardDurGuarded:
        return 2;
    case brdf::WardModel::Gmd:
        return 3;
    }
    return 2;
}

Expected<void> glCheck(const char* what)
{
    if (GLenum err = glGetError(); err != GL_NO_ERROR) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("render: GL error 0x{:04x} while {}", err, what));
    }
    return {};
}

// Channel coefficients per texel, exactly as the CPU model forms them (then rounded to float):
// channels 0-2 in 'a', 3-5 in 'b' (the paper's two RGB float images).
void channelPlanes(const shading::PreparedScene& ps, std::vector<float>& a, std::vector<float>& b)
{
    const surface::SurfaceScene& s = *ps.scene;
    const auto texels = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
    a.assign(texels * 3, 0.0f);
    b.assign(texels * 3, 0.0f);
    for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
            const colour::ChannelCoeffs c = s.channels(ps.paletteCoeffs, x, y);
            const std::size_t i = static_cast<std::size_t>(y) * s.width + x;
            for (std::size_t k = 0; k < 3; ++k) {
                a[i * 3 + k] = static_cast<float>(c[k]);
                b[i * 3 + k] = static_cast<float>(c[3 + k]);
            }
        }
    }
}

std::string boothShaderSource(const BoothShaderConfig& c, const shading::RenderSettings& s)
{
    std::string lightCalls;
    for (int i = 0; i < c.unrolledLights; ++i) {
        lightCalls += fmt::format(" LIGHT_AT({})", i);
    }
    std::string specCalls;
    for (int k = 0; k < c.unrolledSpecularSamples; ++k) {
        specCalls += fmt::format(" SPEC_AT({})", k);
    }
    return fmt::format("#version 310 es\n#define BOOTH_MODE {}\n#define BOOTH_SURROUND {}\n"
                       "#define BOOTH_RELIEF {}\n"
                       "#define BOOTH_GRID {}\n#define BOOTH_DIFFUSE_GRID {}\n"
                       "#define BOOTH_HW_FILTER {}\n"
                       "#define BOOTH_HORIZON_DIRS {}\n#define BOOTH_HORIZON_SLOTS {}\n"
                       "#define BOOTH_SPECULAR {}\n#define BOOTH_WARD_MODEL {}\n"
                       "#define BOOTH_FACET_CACHE {}\n#define BOOTH_LIGHT_CALLS{}\n"
                       "#define BOOTH_UNROLLED_LIGHTS {}\n#define BOOTH_SPEC_CALLS{}\n"
                       "#define BOOTH_UNROLLED_SPEC {}\n#define BOOTH_AREA_LIGHTS {}\n",
                       c.mode, c.surround ? 1 : 0, c.relief ? 1 : 0, c.specularGrid ? 1 : 0,
                       c.diffuseGrid ? 1 : 0, c.hardwareFilter ? 1 : 0, c.horizonDirections,
                       c.horizonSlots, c.specular ? 1 : 0, wardModelIndex(c.wardModel),
                       c.facetCache ? 1 : 0, lightCalls, c.unrolledLights, specCalls,
                       c.unrolledSpecularSamples, s.areaLights ? 1 : 0) +
           // Only a pass that lights with the walls says so: every other program's source stays
           // as it was.
           (s.walls ? "#define BOOTH_WALLS 1\n" : "") + kBoothXyzShader;
}

} // namespace replica::pipeline::render::booth_upload
