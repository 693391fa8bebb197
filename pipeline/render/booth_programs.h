// The booth shading pass's programs: one per shader mode (booth_shaders.h), each compiled from the
// same GLSL with the pass's BOOTH_* defines, and the texture units their samplers read.
#pragma once

#include <array>

#include <GLES3/gl31.h>
#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_walls.h>
#include <pipeline/render/booth_upload.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/view.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::render {

// The texture unit of each booth sampler (uCoeffA ... uDiffGrid).
enum BoothTextureUnit : GLint {
    kUnitCoeffA = 0,
    kUnitCoeffB,
    kUnitNormals,
    kUnitHorizon,
    kUnitLum,
    kUnitCache,
    kUnitSpecGrid,
    kUnitFacet,
    kUnitDiffGrid,
    kUnitCacheMix // the second term a tilt-node interpolation reads (BoothDiffuseCache)
};

// The shader's modes (BOOTH_MODE), and mode 0's second program: the cache's pixels around the
// surface (BOOTH_MODE 0 with BOOTH_SURROUND 1; Cache then draws the surface's alone).
enum class BoothMode : int {
    Cache = 0,
    Compose = 1,
    SpecularGrid = 2,
    DiffuseGrid = 3,
    CacheSurround = 4
};

class BoothPrograms
{
public:
    // Compiles modes 0 to modes - 1 from 'config' (its mode set for each) and the settings'
    // switches, mode 0's surround program beside them, and points every sampler at its unit.
    Expected<void> compile(booth_upload::BoothShaderConfig config,
                           const shading::RenderSettings& settings,
                           int modes);

    // Sets a uniform in every mode's program (where that mode still has it).
    template <typename Fn, typename... Args>
    void uniformAll(Fn fn, const char* name, Args... args) const
    {
        for (const GlProgram& program : programs_) {
            if (const GLuint p = program.get(); p != 0) {
                fn(p, glGetUniformLocation(p, name), args...);
            }
        }
    }
    void set3All(const char* name, const glm::dvec3& v) const;
    // Binds uniform block 'name' to 'binding' in every program that has it (a block a mode does
    // not use is gone from its program).
    void bindBlock(const char* name, GLuint binding) const;
    // Sets the panel pose in one mode's program and makes that program current: each mode draws
    // at its own pose (the cache at the held one).
    void usePose(BoothMode mode, const shading::PanelPose& panel) const;
    // In a pass that lights with the walls (RenderSettings::walls), usePose(Cache, pose) also
    // sets the walls' field for the pose (shading::wallField: uWallE, uWallVec) from these walls
    // lit by the current light on this surface; none (a light without walls): no wall light.
    void setWalls(const booth::WallLight* walls, const surface::SurfaceScene* scene)
    {
        walls_ = walls;
        wallScene_ = scene;
    }

private:
    void setWallField(GLuint program, const shading::PanelPose& panel) const;

    std::array<GlProgram, 5> programs_{};
    bool wallsOn_ = false;
    const booth::WallLight* walls_ = nullptr;
    const surface::SurfaceScene* wallScene_ = nullptr;
};

} // namespace replica::pipeline::render
