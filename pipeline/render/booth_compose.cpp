// The booth shading pass's compose.
#include <pipeline/render/booth_compose.h>

namespace replica::pipeline::render {

void composeBoothFrame(const BoothPrograms& programs,
                       const BoothDiffuseCache& cache,
                       const BoothSpecular& specular,
                       GLuint target,
                       const PixelRect& rect,
                       int width,
                       int height,
                       const shading::PanelPose& panel,
                       bool shadeSurface)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, cache.frontFramebuffer());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
    glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, target);
    if (!shadeSurface) {
        return;
    }
    glEnable(GL_SCISSOR_TEST);
    glScissor(rect.x, rect.y, rect.width, rect.height);
    programs.usePose(BoothMode::Compose, panel);
    glActiveTexture(GL_TEXTURE0 + kUnitCache);
    glBindTexture(GL_TEXTURE_2D, cache.frontTexture());
    glActiveTexture(GL_TEXTURE0 + kUnitFacet);
    glBindTexture(GL_TEXTURE_2D, cache.facetTexture());
    glActiveTexture(GL_TEXTURE0 + kUnitSpecGrid);
    glBindTexture(GL_TEXTURE_2D, specular.gridTexture());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0 + kUnitFacet);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0 + kUnitCache);
    glBindTexture(GL_TEXTURE_2D, 0);
    glDisable(GL_SCISSOR_TEST);
}

} // namespace replica::pipeline::render
