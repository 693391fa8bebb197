// What the booth shading pass reads, uploaded: the scene's textures and the light's.
#include <array>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <pipeline/render/booth_inputs.h>
#include <pipeline/render/booth_shaders.h>

namespace replica::pipeline::render {
using namespace booth_upload;

void BoothInputs::uploadScene(const shading::PreparedScene& ps,
                              bool relief,
                              int horizonDirs,
                              const BoothPrograms& programs)
{
    const surface::SurfaceScene& s = *ps.scene;
    const auto texels = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
    std::vector<float> a, b;
    channelPlanes(ps, a, b);
    coeffA_ = texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, a.data());
    coeffB_ = texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, b.data());

    std::vector<float> n(relief ? texels * 3 : 3, 0.0f);
    if (relief) {
        for (std::size_t i = 0; i < texels; ++i) {
            for (int k = 0; k < 3; ++k) {
                n[i * 3 + static_cast<std::size_t>(k)] = static_cast<float>(ps.normals[i][k]);
            }
        }
    } else {
        n[2] = 1.0f;
    }
    normals_ = relief ? texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, s.width, s.height, n.data())
                      : texture2d(GL_RGB32F, GL_RGB, GL_FLOAT, 1, 1, n.data());

    horizon_ = horizonTexture(ps.horizon, horizonDirs);

    lightsUbo_ = GlBuffer::make();
    glBindBuffer(GL_UNIFORM_BUFFER, lightsUbo_.get());
    // Per light: position and intensity, the two spread vectors, the region's rectangle
    // (glsl/booth_interface.glsl): 16 KiB for 256 lights, the least GL_MAX_UNIFORM_BLOCK_SIZE of
    // GLES 3.1.
    glBufferData(GL_UNIFORM_BUFFER, kBoothMaxLights * 4 * 4 * sizeof(float), nullptr,
                 GL_DYNAMIC_DRAW);
    programs.bindBlock("BoothLights", 0);
}

void BoothInputs::replaceChannels(const shading::PreparedScene& ps)
{
    std::vector<float> a, b;
    channelPlanes(ps, a, b);
    const surface::SurfaceScene& s = *ps.scene;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glBindTexture(GL_TEXTURE_2D, coeffA_.get());
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.width, s.height, GL_RGB, GL_FLOAT, a.data());
    glBindTexture(GL_TEXTURE_2D, coeffB_.get());
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.width, s.height, GL_RGB, GL_FLOAT, b.data());
}

namespace {

// A region's corner in the ceiling's unit coordinates (s, t in [0, 1]).
glm::dvec2 ceilingUnit(const booth::BoothLight& bl, const shading::Vec3& q)
{
    const double u2 = glm::dot(bl.edgeU, bl.edgeU);
    const double v2 = glm::dot(bl.edgeV, bl.edgeV);
    const shading::Vec3 d = q - (bl.centre - 0.5 * (bl.edgeU + bl.edgeV));
    return {u2 > 0.0 ? glm::dot(d, bl.edgeU) / u2 : 0.0,
            v2 > 0.0 ? glm::dot(d, bl.edgeV) / v2 : 0.0};
}

} // namespace

void BoothInputs::uploadLightBlock(const shading::PreparedLight& pl)
{
    const booth::BoothLight& bl = *pl.light;
    const double a = bl.texelAreaM2();
    // The block's four arrays one after another: uLight, uLightSpreadU (w: the region's mean
    // luminance), uLightSpreadV, uLightRect.
    const std::size_t block = static_cast<std::size_t>(kBoothMaxLights) * 4;
    std::vector<float> packed(block * 4, 0.0f);
    for (std::size_t i = 0; i < pl.points.size(); ++i) {
        const booth::PointLight& p = pl.points[i];
        const std::size_t k = i * 4;
        const glm::vec3 pos = f3(p.position);
        const glm::vec3 su = f3(p.spreadU);
        const glm::vec3 sv = f3(p.spreadV);
        for (int c = 0; c < 3; ++c) {
            packed[k + static_cast<std::size_t>(c)] = pos[c];
            packed[block + k + static_cast<std::size_t>(c)] = su[c];
            packed[2 * block + k + static_cast<std::size_t>(c)] = sv[c];
        }
        packed[k + 3] = static_cast<float>(p.sumCdM2 * a);
        packed[block + k + 3] = static_cast<float>(p.meanCdM2);
        const glm::dvec2 lo = ceilingUnit(bl, p.regionOrigin);
        const glm::dvec2 hi = ceilingUnit(bl, p.regionOrigin + p.regionU + p.regionV);
        const std::array<double, 4> rect{lo.x, lo.y, hi.x, hi.y};
        for (std::size_t c = 0; c < 4; ++c) {
            packed[3 * block + k + c] = static_cast<float>(rect[c]);
        }
    }
    glBindBuffer(GL_UNIFORM_BUFFER, lightsUbo_.get());
    glBufferSubData(GL_UNIFORM_BUFFER, 0, static_cast<GLsizeiptr>(packed.size() * sizeof(float)),
                    packed.data());
}

void BoothInputs::uploadMipChain(const shading::PreparedLight& pl, bool hwFilter)
{
    // Exactly as booth::buildMipChain made it (each level uploaded, not regenerated).
    lum_.reset();
    lum_ = GlTexture::make();
    glBindTexture(GL_TEXTURE_2D, lum_.get());
    const auto& levels = pl.mips.levels;
    const int lumMaxLevel = static_cast<int>(levels.size()) - 1;
    glTexStorage2D(GL_TEXTURE_2D, static_cast<GLsizei>(levels.size()), GL_R32F, levels[0].width,
                   levels[0].height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    std::vector<float> level;
    for (std::size_t l = 0; l < levels.size(); ++l) {
        level.assign(levels[l].cdM2.begin(), levels[l].cdM2.end());
        glTexSubImage2D(GL_TEXTURE_2D, static_cast<GLint>(l), 0, 0, levels[l].width,
                        levels[l].height, GL_RED, GL_FLOAT, level.data());
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, lumMaxLevel);
    nearest(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    if (hwFilter) {
        // booth::MipChain::sampleNearestLevel's rule (glsl/mip_chain.glsl lumSample); border
        // colour 0.
        constexpr GLenum kClampToBorder = 0x812D; // GL_CLAMP_TO_BORDER_EXT / _OES
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, kClampToBorder);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, kClampToBorder);
    }
}

Expected<void> BoothInputs::uploadLight(const shading::PreparedLight& pl,
                                        const surface::SurfaceScene& s,
                                        const colour::Observer& observer,
                                        bool hwFilter,
                                        const BoothPrograms& programs)
{
    const booth::BoothLight& bl = *pl.light;
    if (pl.points.size() > static_cast<std::size_t>(kBoothMaxLights)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("render: {} lights; the GL pass holds at most {}: prepare the "
                                     "light with {} or fewer",
                                     pl.points.size(), kBoothMaxLights, kBoothMaxLights));
    }
    uploadLightBlock(pl);
    uploadMipChain(pl, hwFilter);
    const double u2 = glm::dot(bl.edgeU, bl.edgeU);
    const double v2 = glm::dot(bl.edgeV, bl.edgeV);
    const auto& levels = pl.mips.levels;
    const colour::Xyz specXyz = colour::spectrumToXyz(observer, s.rhoS * pl.unitSpd);
    programs.uniformAll(glProgramUniform1i, "uLightCount", static_cast<int>(pl.points.size()));
    programs.set3All("uLightNormal", bl.normal());
    programs.uniformAll(glProgramUniform1f, "uTexelArea", static_cast<float>(bl.texelAreaM2()));
    std::array<float, colour::kChannels * 3> m{};
    for (std::size_t k = 0; k < colour::kChannels; ++k) {
        for (int c = 0; c < 3; ++c) {
            m[k * 3 + static_cast<std::size_t>(c)] = static_cast<float>(pl.channelXyz[k][c]);
        }
    }
    programs.uniformAll(glProgramUniform3fv, "uChannelXyz", static_cast<GLsizei>(colour::kChannels),
                        m.data());
    programs.set3All("uWhite", pl.white);
    programs.set3All("uSpecXyz", specXyz);
    programs.set3All("uLightCentre", bl.centre);
    programs.set3All("uEdgeU", bl.edgeU);
    programs.set3All("uEdgeV", bl.edgeV);
    programs.uniformAll(glProgramUniform2f, "uInvEdge2",
                        static_cast<float>(u2 > 0.0 ? 1.0 / u2 : 0.0),
                        static_cast<float>(v2 > 0.0 ? 1.0 / v2 : 0.0));
    programs.uniformAll(glProgramUniform1i, "uLumMaxLevel", static_cast<int>(levels.size()) - 1);
    programs.uniformAll(glProgramUniform2i, "uLumSize", levels[0].width, levels[0].height);
    programs.uniformAll(glProgramUniform2f, "uLumUsed", static_cast<float>(pl.mips.usedU),
                        static_cast<float>(pl.mips.usedV));
    return glCheck("uploading the light");
}

void BoothInputs::bind() const
{
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, lightsUbo_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitCoeffA);
    glBindTexture(GL_TEXTURE_2D, coeffA_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitCoeffB);
    glBindTexture(GL_TEXTURE_2D, coeffB_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitNormals);
    glBindTexture(GL_TEXTURE_2D, normals_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitHorizon);
    glBindTexture(GL_TEXTURE_2D_ARRAY, horizon_.get());
    glActiveTexture(GL_TEXTURE0 + kUnitLum);
    glBindTexture(GL_TEXTURE_2D, lum_.get());
}

} // namespace replica::pipeline::render
