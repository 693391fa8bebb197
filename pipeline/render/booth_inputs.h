// What the booth shading pass reads, on the GPU: the scene's channel coefficients, normals and
// horizon map, and the light's point lights (a uniform block) and luminance mip chain, with the
// uniforms that describe them.
#pragma once

#include <GLES3/gl31.h>

#include <pipeline/base/expected.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/render/booth_programs.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/shading/realtime_model.h>

namespace replica::pipeline::render {

class BoothInputs
{
public:
    // Uploads the scene: channel coefficients (two RGB32F planes), the normal map with 'relief'
    // (else one flat texel), 'horizonDirs' directions of the horizon map; makes the lights'
    // uniform block (binding 0 in 'programs').
    void uploadScene(const shading::PreparedScene& ps,
                     bool relief,
                     int horizonDirs,
                     const BoothPrograms& programs);
    // Replaces the channel coefficients with those of 'ps' (the same size: checked by the caller).
    void replaceChannels(const shading::PreparedScene& ps);
    // Uploads a light: point lights (at most kBoothMaxLights), luminance mip chain, its uniforms
    // in every program (channel XYZ vectors, the specular colour of 'scene' under it, the
    // ceiling's geometry). 'hwFilter': the chain is filtered by the sampler.
    Expected<void> uploadLight(const shading::PreparedLight& pl,
                               const surface::SurfaceScene& scene,
                               const colour::Observer& observer,
                               bool hwFilter,
                               const BoothPrograms& programs);
    // Binds the textures to their units (booth_programs.h) and the lights' block to binding 0.
    void bind() const;

private:
    // The lights' block: each light's position and intensity, spreads and region rectangle.
    void uploadLightBlock(const shading::PreparedLight& pl);
    // The luminance mip chain, filtered by the sampler with 'hwFilter'.
    void uploadMipChain(const shading::PreparedLight& pl, bool hwFilter);

    GlBuffer lightsUbo_;
    GlTexture coeffA_, coeffB_, normals_, horizon_, lum_;
};

} // namespace replica::pipeline::render
