// The booth shading pass's specular term (paper eq. 3, Ward-Dur by filtered importance
// sampling): the samples' half vectors and solid angles (a uniform block, and their count a
// uniform: each lamp may take its own) and, with a specular grid, the target the term is shaded
// into at the grid's nodes.
#pragma once

#include <pipeline/base/expected.h>
#include <pipeline/render/booth_programs.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/shading/realtime_model.h>

namespace replica::pipeline::render {

class BoothSpecular
{
public:
    // 'samples' half vectors for the surface's roughness (0: no specular term; a block of zeros),
    // bound as binding 1 in 'programs'; a node target when 'grid' has nodes.
    Expected<void> init(const surface::SurfaceScene& s,
                        int samples,
                        shading::GridNodes grid,
                        const BoothPrograms& programs);
    // Replaces the samples with 'samples' of them (each lamp's count, booth_scene_pass.h): the
    // block's table and uSpecSamples in every program.
    void setSamples(const surface::SurfaceScene& s, int samples, const BoothPrograms& programs);
    int samples() const { return samples_; }
    // Binds the samples' block to binding 1.
    void bind() const;
    // This eye's specular term at the grid's nodes (mode 2), for the compose to interpolate;
    // nothing without a grid. Leaves the viewport width x height.
    void
    drawGrid(const BoothPrograms& programs, const shading::PanelPose& panel, int width, int height);
    shading::GridNodes gridNodes() const { return gridNodes_; }
    // The grid's target (0 without a grid).
    GLuint gridTexture() const { return gridTexture_.get(); }

private:
    GlBuffer samplesUbo_;
    int samples_ = 0;
    shading::GridNodes gridNodes_;
    GlTexture gridTexture_;
    GlFramebuffer gridFbo_;
};

} // namespace replica::pipeline::render
