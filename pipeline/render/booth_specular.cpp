// The booth shading pass's specular term: the sample table and the specular grid.
#include <vector>

#include <pipeline/brdf/ward.h>
#include <pipeline/render/booth_shaders.h>
#include <pipeline/render/booth_specular.h>

namespace replica::pipeline::render {

Expected<void> BoothSpecular::init(const surface::SurfaceScene& s,
                                   int samples,
                                   shading::GridNodes grid,
                                   const BoothPrograms& programs)
{
    samplesUbo_ = GlBuffer::make();
    setSamples(s, samples, programs);
    programs.bindBlock("BoothSpecSamples", 1);

    gridNodes_ = grid;
    if (gridNodes_.x > 0) {
        if (auto ok = booth_upload::nodeTarget(gridNodes_, kUnitSpecGrid, "specular", gridTexture_,
                                               gridFbo_);
            !ok) {
            return ok;
        }
    }
    programs.uniformAll(glProgramUniform2i, "uGridNodes", gridNodes_.x, gridNodes_.y);
    return {};
}

void BoothSpecular::setSamples(const surface::SurfaceScene& s,
                               int samples,
                               const BoothPrograms& programs)
{
    // The samples' half vectors depend only on alpha and N: computed here, in double, whenever N
    // changes (the same N gives the same table, so a lamp switch back draws the same frame).
    std::vector<float> table(static_cast<std::size_t>(kBoothMaxSpecularSamples) * 4, 0.0f);
    for (int k = 0; k < samples; ++k) {
        const double u1 = (k + 0.5) / samples;
        const shading::Vec3 hl = brdf::sampleWardHalfVectorLocal(
                s.alpha, u1, shading::radicalInverse2(static_cast<unsigned>(k)));
        const double w = brdf::wardSolidAngleWithoutOh(s.alpha, hl.z, u1, samples);
        const auto i = static_cast<std::size_t>(k) * 4;
        table[i] = static_cast<float>(hl.x);
        table[i + 1] = static_cast<float>(hl.y);
        table[i + 2] = static_cast<float>(hl.z);
        table[i + 3] = static_cast<float>(w);
    }
    glBindBuffer(GL_UNIFORM_BUFFER, samplesUbo_.get());
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(table.size() * sizeof(float)),
                 table.data(), GL_STATIC_DRAW);
    programs.uniformAll(glProgramUniform1i, "uSpecSamples", samples);
    samples_ = samples;
}

void BoothSpecular::bind() const
{
    glBindBufferBase(GL_UNIFORM_BUFFER, 1, samplesUbo_.get());
}

void BoothSpecular::drawGrid(const BoothPrograms& programs,
                             const shading::PanelPose& panel,
                             int width,
                             int height)
{
    if (gridNodes_.x <= 0) {
        return;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, gridFbo_.get());
    glViewport(0, 0, gridNodes_.x, gridNodes_.y);
    programs.usePose(BoothMode::SpecularGrid, panel);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glViewport(0, 0, width, height);
}

} // namespace replica::pipeline::render
