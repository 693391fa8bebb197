// The booth shading pass's cache of the eye-independent part of a frame: the diffuse term (paper
// eq. 1 and 2) in XYZ and E_geo, the illuminance on the panel plane, in alpha; with relief and a
// per-pixel specular term also each pixel's facet normal; on a flat surface the diffuse grid it
// interpolates E_geo from. Two buffers, each labelled with what it holds; it draws what it is
// asked (a term whole, or band b of K of one) and keeps no schedule: the state stage decides
// which band a frame draws (pipeline/scene/diffuse_schedule.h).
#pragma once

#include <algorithm>
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

// What a frame asks of the cache: the term composed at 'shown', and (a sliced refresh under way)
// band 'band' of 'bands' of the term at 'toward', drawn into the second buffer; the last band
// makes that buffer the one composed ('shown' is then 'toward').
struct CacheBand {
    shading::PanelPose toward;
    int band = 0;
    int bands = 1;
};
// With tilt nodes (init's 'nodes') the term composed is (1 - mix) times the term at 'shown' plus
// mix times the term at 'mixWith' (scene::DiffuseDraw); 'band' then draws a node.
struct CacheWant {
    shading::PanelPose shown;
    std::optional<CacheBand> band;
    std::optional<shading::PanelPose> mixWith{};
    double mix = 0.0;
};

class BoothDiffuseCache
{
public:
    // 'slices' (settings.cacheSlices): bands a pose change is redrawn in; 'nodes'
    // (settings.tiltNodesRad > 0): keep the terms of several poses and compose two of them
    // interpolated, as CacheWant names; 'facetCache': keep the facet normals; 'diffuseGrid': the
    // diffuse grid's nodes (none: per pixel), holding eq. (1) with the facets too on 'relief'.
    Expected<void> init(int slices,
                        bool nodes,
                        bool facetCache,
                        shading::GridNodes diffuseGrid,
                        bool relief,
                        const BoothPrograms& programs);

    // Makes the cache's targets width x height (new ones, holding nothing, on a size change).
    Expected<void> ensureTarget(int width, int height);
    // Makes the buffers hold what 'want' names, for 'layout' ('rect': its surfaceRect): where
    // they already hold the term shown and the refresh's earlier bands, the one band asked for;
    // otherwise (a fresh cache, a new light, size, layout, channels or surround, frame N drawn
    // alone) the term shown whole, then the refresh's bands so far. A band at the same pose,
    // size and layout as the whole term is the same pixels, so either way the frame is the same.
    void update(const BoothPrograms& programs,
                const CacheWant& want,
                const SurfaceLayout& layout,
                const PixelRect& rect,
                int width,
                int height);

    // Forgets what both buffers hold: the next update draws the term whole.
    void invalidate()
    {
        front_.reset();
        back_.reset();
        for (Slot& s : slots_) {
            s.key.reset();
        }
        mixedFor_.reset();
    }
    // BoothShadingPass::setSurroundIlluminance.
    void setSurroundIlluminance(bool on);
    bool surroundIlluminance() const { return surroundIlluminance_; }
    long refreshes() const { return refreshes_; }
    // Whether a sliced refresh is under way (some of its bands drawn, the frame composed from the
    // other buffer).
    bool refreshPending() const
    {
        return back_.has_value() || std::any_of(slots_.begin(), slots_.end(), [](const Slot& s) {
                   return s.key && s.bands < s.slices;
               });
    }
    // With tilt nodes: the poses' terms held whole (at most kNodeSlots).
    int nodesHeld() const
    {
        return static_cast<int>(std::count_if(slots_.begin(), slots_.end(), [](const Slot& s) {
            return s.key && s.bands == s.slices;
        }));
    }

    // The complete cache the frame composes from: its framebuffer and texture, and the facet
    // normals (0 without).
    GLuint frontFramebuffer() const { return front().fbo.get(); }
    GLuint frontTexture() const { return front().texture.get(); }
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
    // What the second buffer holds of a sliced refresh: the key it is drawn for and how many
    // bands of it.
    struct Partial {
        Key key;
        int bands = 0;
    };
    // With tilt nodes: a buffer holding a pose's term, whole (bands == slices) or the first
    // 'bands' of its 'slices', and the update it was last used in.
    struct Slot {
        Buffer buffer;
        std::optional<Key> key;
        int bands = 0;
        int slices = 1;
        long used = 0;
    };
    // The nodes the state stage keeps (scene::kMaxDiffuseNodes), the one drawn in bands, and a
    // spare: where the two forget different nodes, the one forgotten here can be one kept there.
    static constexpr std::size_t kNodeSlots = 6;
    // What the interpolated buffer holds.
    struct MixKey {
        Key a, b;
        float mix = 0.0f;
        bool operator==(const MixKey&) const = default;
    };
    const Buffer& front() const
    {
        return frontBuffer_ != nullptr ? *frontBuffer_ : buffers_[static_cast<std::size_t>(shown_)];
    }
    // The buffer's texture and framebuffer, width_ x height_ (the facet texture beside it).
    bool makeBuffer(Buffer& c, bool facet);
    // CacheWant with tilt nodes (update()).
    void updateNodes(const BoothPrograms& programs,
                     const CacheWant& want,
                     const SurfaceLayout& layout,
                     const PixelRect& rect);
    // The node slot for 'key' (whole or not), or none.
    Slot* findSlot(const Key& key);
    // A slot for a new key: an empty one, else one of another size or layout than 'frame' (the
    // frame's term shown), else the one whose pose is farthest from it; never one used in this
    // update. Its buffer is made on first use.
    Slot& freeSlot(const Key& frame);
    // The term at 'pose' whole into 'slot' (the refreshes' bands elsewhere forgotten where a
    // diffuse grid is drawn: they were drawn with another pose's).
    void drawNodeWhole(const BoothPrograms& programs,
                       Slot& slot,
                       const Key& key,
                       const shading::PanelPose& pose,
                       const PixelRect& rect);
    Key keyOf(const shading::PanelPose& pose, const SurfaceLayout& layout, int w, int h) const
    {
        return {pose.centre, pose.right, pose.up, pose.normal, w, h, layout.offset, layout.scale};
    }
    // Band 'slice' of 'slices' of a refresh (slice 0 also draws the diffuse grid and clears what
    // needs clearing), for a frame of width x height whose surface is 'rect', of which 'interior'
    // (surfaceInterior) is surely on the surface: what mode 0's surround program leaves out.
    struct Band {
        int slice = 0;
        int slices = 1;
        PixelRect rect;
        PixelRect interior;
        int width = 0;
        int height = 0;
    };
    static PixelRect interiorOf(const Key& k)
    {
        return surfaceInterior(SurfaceLayout{k.offset, k.scale}, k.width, k.height);
    }
    // The term whole into the buffer composed; band 'band' into the other one.
    void drawWhole(const BoothPrograms& programs,
                   const Key& key,
                   const shading::PanelPose& pose,
                   const PixelRect& rect);
    void drawBand(const BoothPrograms& programs,
                  const Key& key,
                  const CacheBand& band,
                  const PixelRect& rect);
    // Draws the eye-independent part at 'pose' into buffers_[buffer], band 'band'.
    void drawSlice(const BoothPrograms& programs,
                   Buffer& c,
                   const shading::PanelPose& pose,
                   const Band& band);

    int slices_ = 1;
    bool nodes_ = false;
    bool facetCache_ = false;
    bool surroundIlluminance_ = true;
    long refreshes_ = 0;
    // The buffer the frames compose from and what it holds (none: nothing known), and (slices_ >
    // 1 only) what the other one holds of a sliced refresh.
    std::array<Buffer, 2> buffers_{};
    int shown_ = 0;
    std::optional<Key> front_;
    std::optional<Partial> back_;
    // One texture behind both buffers: a facet normal depends on the layout and size alone, and a
    // change of either redraws the cache whole, so a band drawn into the back buffer writes there
    // what it already holds.
    GlTexture facetTexture_;
    int width_ = 0, height_ = 0;
    // Tilt nodes: the slots, the interpolated term and what it holds, the program that draws it,
    // and the buffer this update composes from (none: buffers_[shown_]).
    std::array<Slot, kNodeSlots> slots_{};
    long updates_ = 0;
    Buffer mixed_;
    std::optional<MixKey> mixedFor_;
    GlProgram mixProgram_;
    GLint mixLocation_ = -1;
    const Buffer* frontBuffer_ = nullptr;
    // The diffuse grid (on a flat surface): E_geo at its nodes, drawn with the cache (mode 3).
    shading::GridNodes diffuseNodes_;
    GlTexture diffuseTexture_;
    GlFramebuffer diffuseFbo_;
};

} // namespace replica::pipeline::render
