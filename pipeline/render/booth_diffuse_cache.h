// The booth shading pass's cache of the eye-independent part of a frame: the diffuse term (paper
// eq. 1 and 2) in XYZ and E_geo, the illuminance on the panel plane, in alpha; with relief and a
// per-pixel specular term also each pixel's facet normal; on a flat surface the diffuse grid it
// interpolates E_geo from. Recomputed only when what it was drawn for changes
// (BoothShadingPass::draw says when, and how a sliced refresh proceeds).
#pragma once

#include <array>
#include <optional>

#include <GLES3/gl31.h>

#include <pipeline/base/expected.h>
#include <pipeline/render/booth_programs.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/render/pixel_rect.h>
#include <pipeline/render/surface_layout.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/view.h>

namespace replica::pipeline::render {

class BoothDiffuseCache
{
public:
    // 'slices' (settings.cacheSlices): bands a pose change is redrawn in; 'facetCache': keep the
    // facet normals; 'diffuseGrid': the diffuse grid's nodes (none: per pixel).
    Expected<void> init(int slices,
                        bool facetCache,
                        shading::GridNodes diffuseGrid,
                        const BoothPrograms& programs);

    // Makes the cache's targets width x height (new ones, holding nothing, on a size change).
    Expected<void> ensureTarget(int width, int height);
    // Brings the cache up to date for 'pose' and 'layout' (BoothShadingPass::draw's rule): drawn
    // whole, or the next band of a sliced refresh. 'rect': surfaceRect of the layout.
    void update(const BoothPrograms& programs,
                const shading::PanelPose& pose,
                const SurfaceLayout& layout,
                const PixelRect& rect,
                int width,
                int height);

    // Forces the next update to draw the cache whole.
    void invalidate() { valid_ = false; }
    // BoothShadingPass::setSurroundIlluminance.
    void setSurroundIlluminance(bool on);
    bool surroundIlluminance() const { return surroundIlluminance_; }
    long refreshes() const { return refreshes_; }
    bool refreshPending() const { return pending_.has_value(); }

    // The complete cache the frame composes from: its framebuffer and texture, and the facet
    // normals (0 without).
    GLuint frontFramebuffer() const { return buffers_[static_cast<std::size_t>(front_)].fbo.get(); }
    GLuint frontTexture() const { return buffers_[static_cast<std::size_t>(front_)].texture.get(); }
    GLuint facetTexture() const { return facetTexture_.get(); }

private:
    // What a cache was drawn for.
    struct Key {
        shading::Vec3 centre{0.0}, right{0.0}, up{0.0}, normal{0.0};
        int width = 0, height = 0;
        glm::dvec2 offset{0.0}, scale{0.0};
        bool operator==(const Key&) const = default;
    };
    struct Buffer {
        GlTexture texture; // RGBA32F: diffuse XYZ, E_geo in alpha
        GlFramebuffer fbo;
        // The rectangle outside which this buffer is known to hold zero (cleared for it, and mode
        // 0 writes only inside it); none after a new texture or a draw with the surround's
        // illuminance.
        std::optional<PixelRect> zeroAround;
    };
    // A sliced refresh under way: the key and pose it draws, and its next band.
    struct PendingRefresh {
        Key key;
        shading::PanelPose pose;
        int nextSlice = 0;
    };
    // Band 'slice' of 'slices' of a refresh (slice 0 also draws the diffuse grid and clears what
    // needs clearing), for a frame of width x height whose surface is 'rect'.
    struct Band {
        int slice = 0;
        int slices = 1;
        PixelRect rect;
        int width = 0;
        int height = 0;
    };
    // Draws the eye-independent part at 'pose' into buffers_[buffer], band 'band'.
    void drawSlice(const BoothPrograms& programs,
                   int buffer,
                   const shading::PanelPose& pose,
                   const Band& band);

    int slices_ = 1;
    bool facetCache_ = false;
    // key_: what the front buffer holds when valid_.
    Key key_;
    bool valid_ = false;
    bool surroundIlluminance_ = true;
    long refreshes_ = 0;
    // The front buffer the frames compose from, and (slices_ > 1 only) the back one a sliced
    // refresh draws into.
    std::array<Buffer, 2> buffers_{};
    int front_ = 0;
    std::optional<PendingRefresh> pending_;
    // One texture behind both buffers: a facet normal depends on the layout and size alone, and a
    // change of either redraws the cache whole, so a band drawn into the back buffer writes there
    // what it already holds.
    GlTexture facetTexture_;
    int width_ = 0, height_ = 0;
    // The diffuse grid (on a flat surface): E_geo at its nodes, drawn with the cache (mode 3).
    shading::GridNodes diffuseNodes_;
    GlTexture diffuseTexture_;
    GlFramebuffer diffuseFbo_;
};

} // namespace replica::pipeline::render
