// BoothScenePass::warmUp and warmUpVariant: a shading pass drawn once into a small target of its
// own, so that no frame pays for the shader's first-use compilation.
#include <chrono>

#include <GLES3/gl31.h>

#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/xyz_target.h>
#include <pipeline/scene/stand.h>

namespace replica::pipeline::render {

Expected<double> BoothScenePass::warmUp(int width, int height)
{
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t v = 0; v < variants_.size(); ++v) {
        if (auto ms = warmUpVariant(v, width, height); !ms) {
            return tl::unexpected(ms.error());
        }
    }
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
}

Expected<double> BoothScenePass::warmUpVariant(std::size_t v, int width, int height)
{
    const auto start = std::chrono::steady_clock::now();
    if (auto ok = makeVariant(v); !ok) {
        return tl::unexpected(ok.error());
    }
    // What is bound now (before the target of our own, whose creation binds it) comes back.
    GLint framebuffer = 0;
    GLint viewport[4] = {0, 0, 0, 0};
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
    glGetIntegerv(GL_VIEWPORT, viewport);
    const auto restore = [&] {
        glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(framebuffer));
        glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    };
    auto target = XyzTarget::create(width, height);
    if (!target) {
        restore();
        return tl::unexpected(target.error());
    }
    const long before = cacheRefreshes() + warmUpRefreshes_;
    // The view the loop starts from (the stand's default tilt and eye do not matter: the code
    // compiled is the same for every view).
    shading::View view;
    view.panel = scene::panelPose(setup_.stand, scene::degreesToRadians(30.0));
    view.eye = {0.0, 0.45, 0.60};
    view.pixelsX = width;
    view.pixelsY = height;
    // A lamp drawn with this pass (variant 0 may have none: the direct-sensor mode's).
    const booth::BoothLight* light = &setup_.booth.lights.front();
    const shading::RenderSettings* counts = &setup_.settings;
    for (std::size_t l = 0; l < lampVariant_.size(); ++l) {
        if (lampVariant_[l] == v) {
            light = &setup_.booth.lights[l];
            counts = &lampSettings_[l];
            break;
        }
    }
    BoothShadingPass& pass = *variants_[v].pass;
    if (auto ok = pass.setCounts(counts->lights, counts->specularSamples); !ok) {
        restore();
        return tl::unexpected(ok.error());
    }
    // warmLight_, not light_ (the active pass's): a pass that is not the active one gets its
    // lamp's light from selectLight (a switch to it is a change of light) before it draws a
    // frame; the active one is told to select its light afresh at the next draw.
    warmLight_ =
            shading::prepareLight(*light, setup_.observer, pass.settings().lights, setup_.basis);
    if (v == active_) {
        heldLight_.reset();
    }
    if (auto ok = pass.setLight(warmLight_); !ok) {
        restore();
        return tl::unexpected(ok.error());
    }
    (*target)->bind();
    if (auto ok = pass.draw(view, width, height, layoutOnPanel(setup_.scene, setup_.stand)); !ok) {
        restore();
        return tl::unexpected(ok.error());
    }
    glFinish(); // the compilation is done once the frame is
    pass.invalidateCache();
    drawn_[v] = true;
    restore();
    warmUpRefreshes_ += cacheRefreshes() + warmUpRefreshes_ - before;
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
}

} // namespace replica::pipeline::render
