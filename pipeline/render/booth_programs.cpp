// The booth shading pass's programs.
#include <string>

#include <fmt/format.h>

#include <pipeline/render/booth_programs.h>
#include <pipeline/render/gl_program.h>
#include <pipeline/shading/wall_field.h>

namespace replica::pipeline::render {

Expected<void> BoothPrograms::compile(booth_upload::BoothShaderConfig config,
                                      const shading::RenderSettings& settings,
                                      int modes)
{
    wallsOn_ = settings.walls;
    const auto link = [&](BoothMode slot, int mode, bool surround) -> Expected<void> {
        config.mode = mode;
        config.surround = surround;
        const std::string source = booth_upload::boothShaderSource(config, settings);
        auto program = linkProgram(
                kFullscreenVertexShader, source.c_str(),
                fmt::format("booth XYZ mode {}{}", mode, surround ? " (surround)" : "").c_str());
        if (!program) {
            return tl::unexpected(program.error());
        }
        programs_[static_cast<std::size_t>(slot)] = std::move(*program);
        return {};
    };
    for (int mode = 0; mode < modes; ++mode) {
        if (auto ok = link(static_cast<BoothMode>(mode), mode, false); !ok) {
            return ok;
        }
    }
    if (auto ok = link(BoothMode::CacheSurround, 0, true); !ok) {
        return ok;
    }
    uniformAll(glProgramUniform1i, "uCoeffA", kUnitCoeffA);
    uniformAll(glProgramUniform1i, "uCoeffB", kUnitCoeffB);
    uniformAll(glProgramUniform1i, "uNormals", kUnitNormals);
    uniformAll(glProgramUniform1i, "uHorizon", kUnitHorizon);
    uniformAll(glProgramUniform1i, "uLum", kUnitLum);
    uniformAll(glProgramUniform1i, "uCache", kUnitCache);
    uniformAll(glProgramUniform1i, "uSpecGrid", kUnitSpecGrid);
    uniformAll(glProgramUniform1i, "uFacetCache", kUnitFacet);
    uniformAll(glProgramUniform1i, "uDiffGrid", kUnitDiffGrid);
    return {};
}

void BoothPrograms::set3All(const char* name, const glm::dvec3& v) const
{
    const glm::vec3 f = booth_upload::f3(v);
    uniformAll(glProgramUniform3f, name, f.x, f.y, f.z);
}

void BoothPrograms::bindBlock(const char* name, GLuint binding) const
{
    for (const GlProgram& program : programs_) {
        const GLuint p = program.get();
        if (const GLuint block = p != 0 ? glGetUniformBlockIndex(p, name) : GL_INVALID_INDEX;
            block != GL_INVALID_INDEX) {
            glUniformBlockBinding(p, block, binding);
        }
    }
}

void BoothPrograms::usePose(BoothMode mode, const shading::PanelPose& panel) const
{
    const GLuint p = programs_[static_cast<std::size_t>(mode)].get();
    const auto set = [p](const char* name, const shading::Vec3& v) {
        const glm::vec3 f = booth_upload::f3(v);
        glProgramUniform3f(p, glGetUniformLocation(p, name), f.x, f.y, f.z);
    };
    set("uCentre", panel.centre);
    set("uRight", panel.right);
    set("uUp", panel.up);
    set("uNormal", panel.normal);
    if ((mode == BoothMode::Cache || mode == BoothMode::CacheSurround) && wallsOn_) {
        setWallField(p, panel);
    }
    glUseProgram(p);
}

void BoothPrograms::setWallField(GLuint program, const shading::PanelPose& panel) const
{
    shading::WallField field;
    if (walls_ != nullptr && wallScene_ != nullptr) {
        field = shading::wallField(*walls_, panel, *wallScene_);
    }
    std::array<float, 9> e{};
    for (std::size_t k = 0; k < e.size(); ++k) {
        e[k] = static_cast<float>(field.nodes[k]);
    }
    glProgramUniform1fv(program, glGetUniformLocation(program, "uWallE"), 9, e.data());
    const glm::vec3 v = booth_upload::f3(field.vector);
    glProgramUniform3f(program, glGetUniformLocation(program, "uWallVec"), v.x, v.y, v.z);
}

} // namespace replica::pipeline::render
