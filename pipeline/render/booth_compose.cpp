// The booth shading pass's compose.
#include <pipeline/render/booth_compose.h>

namespace replica::pipeline::render {

void composeBoothFrame(const BoothPrograms& programs,
                       const BoothDiffuseCache& cache,
                       const BoothSpecular& specular,
                       const BoothFrameTarget& target,
                       const shading::PanelPose& panel,
                       bool shadeSurface)
{
    const int w = target.width;
    const int h = target.height;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, cache.frontFramebuffer());
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.framebuffer);
    glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
    if (!shadeSurface) {
        return;
    }
    glEnable(GL_SCISSOR_TEST);
    glScissor(target.rect.x, target.rect.y, target.rect.width, target.rect.height);
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
