// The booth shading pass's cache of the eye-independent part.
#include <algorithm>
#include <array>

#include <glm/geometric.hpp>

#include <pipeline/render/booth_diffuse_cache.h>
#include <pipeline/render/gl_program.h>

namespace replica::pipeline::render {

namespace {

// The tilt nodes' interpolation: (1 - uMix) a + uMix b, texel for texel.
constexpr const char* kMixShader = R"(#version 310 es
precision highp float;
uniform highp sampler2D uA;
uniform highp sampler2D uB;
uniform float uMix;
layout(location = 0) out vec4 outXyz;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    outXyz = mix(texelFetch(uA, p, 0), texelFetch(uB, p, 0), uMix);
}
)";

} // namespace

Expected<void> BoothDiffuseCache::init(int slices,
                                       bool nodes,
                                       bool facetCache,
                                       shading::GridNodes diffuseGrid,
                                       bool relief,
                                       const BoothPrograms& programs)
{
    slices_ = std::max(slices, 1);
    nodes_ = nodes;
    facetCache_ = facetCache;
    if (nodes_) {
        auto program = linkProgram(kFullscreenVertexShader, kMixShader, "tilt-node interpolation");
        if (!program) {
            return tl::unexpected(program.error());
        }
        mixProgram_ = std::move(*program);
        const GLuint p = mixProgram_.get();
        glProgramUniform1i(p, glGetUniformLocation(p, "uA"), kUnitCache);
        glProgramUniform1i(p, glGetUniformLocation(p, "uB"), kUnitCacheMix);
        mixLocation_ = glGetUniformLocation(p, "uMix");
    }
    diffuseNodes_ = diffuseGrid;
    if (diffuseNodes_.x > 0) {
        if (auto ok = booth_upload::nodeTarget(diffuseNodes_, kUnitDiffGrid, "diffuse",
                                               diffuseTexture_, diffuseFbo_, relief);
            !ok) {
            return ok;
        }
    }
    programs.uniformAll(glProgramUniform2i, "uDiffNodes", diffuseNodes_.x, diffuseNodes_.y);
    return {};
}

void BoothDiffuseCache::setSurroundIlluminance(bool on)
{
    if (on != surroundIlluminance_) {
        surroundIlluminance_ = on;
        invalidate();
    }
}

Expected<void> BoothDiffuseCache::ensureTarget(int width, int height)
{
    const Buffer& first = nodes_ ? slots_[0].buffer : buffers_[0];
    if (first.texture && width_ == width && height_ == height) {
        return {};
    }
    for (Buffer& c : buffers_) {
        c = Buffer{}; // a new texture holds nothing yet
    }
    for (Slot& s : slots_) {
        s = Slot{};
    }
    mixed_ = Buffer{};
    frontBuffer_ = nullptr;
    facetTexture_.reset();
    shown_ = 0;
    invalidate();
    width_ = width;
    height_ = height;
    glActiveTexture(GL_TEXTURE0 + kUnitCache); // texture2d binds it: not over another input
    if (facetCache_) {
        facetTexture_ = texture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, width, height, nullptr);
    }
    // The back buffer only where refreshes are sliced: 9 MB at 960x600 that nothing else reads.
    // With tilt nodes the slots' buffers are made as they are first used, and the first holds
    // the first frame's term.
    const int buffers = nodes_ ? 0 : (slices_ > 1 ? 2 : 1);
    bool complete = true;
    for (int b = 0; b < buffers; ++b) {
        complete = makeBuffer(buffers_[static_cast<std::size_t>(b)], facetCache_) && complete;
    }
    if (nodes_) {
        complete = makeBuffer(slots_[0].buffer, facetCache_) && complete;
    }
    if (!complete) {
        return makeError(ErrorCode::Unsupported,
                         "render: the booth pass's RGBA32F cache is not renderable on this GL");
    }
    return booth_upload::glCheck("creating the booth pass's cache");
}

bool BoothDiffuseCache::makeBuffer(Buffer& c, bool facet)
{
    glActiveTexture(GL_TEXTURE0 + kUnitCache); // texture2d binds it: not over another input
    c.texture = texture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, width_, height_, nullptr);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
    c.fbo = GlFramebuffer::make();
    c.zeroAround.reset();
    glBindFramebuffer(GL_FRAMEBUFFER, c.fbo.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, c.texture.get(), 0);
    if (facet) {
        // Mode 0 writes the facet normal beside the cached terms; the blit reads attachment 0.
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D,
                               facetTexture_.get(), 0);
        const std::array<GLenum, 2> attachments{GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        glDrawBuffers(2, attachments.data());
        glReadBuffer(GL_COLOR_ATTACHMENT0);
    }
    return glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
}

void BoothDiffuseCache::update(const BoothPrograms& programs,
                               const CacheWant& want,
                               const SurfaceLayout& layout,
                               const PixelRect& rect,
                               int width,
                               int height)
{
    if (nodes_) {
        updateNodes(programs, want, layout, rect);
        return;
    }
    const Key shown = keyOf(want.shown, layout, width, height);
    if (!want.band) {
        if (front_ != shown) {
            drawWhole(programs, shown, want.shown, rect);
        }
        return;
    }
    const CacheBand& band = *want.band;
    const Key toward = keyOf(band.toward, layout, width, height);
    const bool last = band.band + 1 >= band.bands;
    // The one draw, where the buffers hold what the frame before it drew: the band asked for.
    const bool earlierBands =
            band.band == 0 || (back_ && back_->key == toward && back_->bands == band.band);
    if (earlierBands && (last || front_ == shown) && slices_ > 1) {
        drawBand(programs, toward, band, rect);
        return;
    }
    // Otherwise the term shown whole (the last band's frame shows the refresh's tilt: whole, it is
    // the same pixels), then the refresh's bands so far.
    if (front_ != shown) {
        drawWhole(programs, shown, want.shown, rect);
    }
    if (last || slices_ == 1) {
        return;
    }
    for (int b = 0; b <= band.band; ++b) {
        drawBand(programs, toward, {band.toward, b, band.bands}, rect);
    }
}

void BoothDiffuseCache::drawWhole(const BoothPrograms& programs,
                                  const Key& key,
                                  const shading::PanelPose& pose,
                                  const PixelRect& rect)
{
    // A refresh's bands in the other buffer were drawn with the diffuse grid of its tilt, which
    // this draw replaces: they are of no use any more.
    back_.reset();
    drawSlice(programs, buffers_[static_cast<std::size_t>(shown_)], pose,
              {0, 1, rect, interiorOf(key), key.width, key.height});
    front_ = key;
    ++refreshes_;
}

void BoothDiffuseCache::drawBand(const BoothPrograms& programs,
                                 const Key& key,
                                 const CacheBand& band,
                                 const PixelRect& rect)
{
    const int back = 1 - shown_;
    drawSlice(programs, buffers_[static_cast<std::size_t>(back)], band.toward,
              {band.band, band.bands, rect, interiorOf(key), key.width, key.height});
    back_ = Partial{key, band.band + 1};
    if (band.band + 1 == band.bands) {
        // The last band: that buffer is the one composed from now on.
        shown_ = back;
        front_ = key;
        back_.reset();
        ++refreshes_;
    }
}

void BoothDiffuseCache::drawSlice(const BoothPrograms& programs,
                                  Buffer& c,
                                  const shading::PanelPose& pose,
                                  const Band& band)
{
    const int slice = band.slice;
    const int slices = band.slices;
    const PixelRect& rect = band.rect;
    const int width = band.width;
    const int height = band.height;
    if (slice == 0 && diffuseNodes_.x > 0) {
        // E_geo at the diffuse grid's nodes (and on relief eq. (1) with the facets), for mode 0
        // to interpolate on the surface (it stays for the refresh's later bands: nothing else
        // draws into it).
        glBindFramebuffer(GL_FRAMEBUFFER, diffuseFbo_.get());
        glViewport(0, 0, diffuseNodes_.x, diffuseNodes_.y);
        programs.usePose(BoothMode::DiffuseGrid, pose);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glViewport(0, 0, width, height);
    }
    if (diffuseNodes_.x > 0) {
        glActiveTexture(GL_TEXTURE0 + kUnitDiffGrid);
        glBindTexture(GL_TEXTURE_2D, diffuseTexture_.get());
        glActiveTexture(GL_TEXTURE0);
    }
    // Every pixel: the diffuse term on the surface, E_geo on the whole panel (the flare); or,
    // without the surround's illuminance, the surface's rectangle and zero around it.
    glBindFramebuffer(GL_FRAMEBUFFER, c.fbo.get());
    PixelRect region{0, 0, width, height};
    if (!surroundIlluminance_) {
        // Mode 0 writes only the rectangle, so zero around it stays zero from one refresh to
        // the next: cleared only when the buffer was not already zero there (a new target, a
        // new rectangle, or the surround's illuminance drawn). On llvmpipe a clear of the
        // RGBA32F cache is a pass over 9 MB at 960x600, a good part of a tilting frame.
        if (slice == 0 && !(c.zeroAround && *c.zeroAround == rect)) {
            const std::array<float, 4> zero{};
            glClearBufferfv(GL_COLOR, 0, zero.data());
            c.zeroAround = rect;
        }
        region = rect;
    } else {
        c.zeroAround.reset();
    }
    // Band 'slice' of the region's rows: the surface's rows split evenly (they carry nearly all
    // the cost), the rows below it with the first band and those above with the last.
    int y0 = region.y;
    int y1 = region.y + region.height;
    if (slices > 1) {
        const auto edge = [&](int k) {
            return rect.y + static_cast<int>(static_cast<long>(rect.height) * k / slices);
        };
        y0 = slice == 0 ? region.y : edge(slice);
        y1 = slice == slices - 1 ? region.y + region.height : edge(slice + 1);
    }
    // Mode 0 is two programs (booth_main.glsl): the surface's over its rectangle, then the
    // surround's over the rest of the region and the rectangle's margin (the pixels between the
    // interior, surely on the surface, and the rectangle's edge), discarding the surface's pixels
    // and overwriting the margin's others. Same pixels as one program over the region, without
    // the surround's light loop on every pixel of the surface (llvmpipe ran it under a mask: 5.4
    // of the ColorChecker's 7.9 ms).
    glEnable(GL_SCISSOR_TEST);
    const auto drawRows = [&](BoothMode mode, int x, int ya, int w, int yb) {
        const int lo = std::max(ya, y0);
        const int hi = std::min(yb, y1);
        if (w > 0 && hi > lo) {
            glScissor(x, lo, w, hi - lo);
            programs.usePose(mode, pose);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
    };
    drawRows(BoothMode::Cache, rect.x, rect.y, rect.width, rect.y + rect.height);
    const PixelRect& in = band.interior;
    const int regionTop = region.y + region.height;
    if (in.width <= 0 || in.height <= 0) {
        drawRows(BoothMode::CacheSurround, region.x, region.y, region.width, regionTop);
    } else {
        // Below the interior, above it, and beside it to the left and right.
        drawRows(BoothMode::CacheSurround, region.x, region.y, region.width, in.y);
        drawRows(BoothMode::CacheSurround, region.x, in.y + in.height, region.width, regionTop);
        drawRows(BoothMode::CacheSurround, region.x, in.y, in.x - region.x, in.y + in.height);
        drawRows(BoothMode::CacheSurround, in.x + in.width, in.y,
                 region.x + region.width - (in.x + in.width), in.y + in.height);
    }
    glDisable(GL_SCISSOR_TEST);
    if (diffuseNodes_.x > 0) {
        glActiveTexture(GL_TEXTURE0 + kUnitDiffGrid);
        glBindTexture(GL_TEXTURE_2D, 0); // not sampled while mode 3 draws into it
        glActiveTexture(GL_TEXTURE0);
    }
}

BoothDiffuseCache::Slot* BoothDiffuseCache::findSlot(const Key& key)
{
    for (Slot& s : slots_) {
        if (s.key && *s.key == key) {
            return &s;
        }
    }
    return nullptr;
}

BoothDiffuseCache::Slot& BoothDiffuseCache::freeSlot(const Key& frame)
{
    // An empty slot, else one drawn for another size or layout (of no use again), else the one
    // whose pose is farthest from the frame's (the state stage forgets the node farthest from the
    // held tilt: scene::nextDiffuseNodes).
    Slot* pick = nullptr;
    double farthest = 2.0;
    for (Slot& s : slots_) {
        if (!s.key) {
            pick = &s;
            break;
        }
        if (s.used == updates_) {
            continue;
        }
        const Key& k = *s.key;
        const bool stale = k.width != frame.width || k.height != frame.height ||
                           k.offset != frame.offset || k.scale != frame.scale;
        const double facing = stale ? -2.0 : glm::dot(k.normal, frame.normal);
        if (pick == nullptr || facing < farthest) {
            pick = &s;
            farthest = facing;
        }
    }
    // A frame names at most three poses (shown, mixed with, drawn in bands), so of kNodeSlots
    // one is always free or unused this update.
    if (!pick->buffer.texture) {
        makeBuffer(pick->buffer, facetCache_);
    }
    pick->key.reset();
    pick->bands = 0;
    return *pick;
}

void BoothDiffuseCache::drawNodeWhole(const BoothPrograms& programs,
                                      Slot& slot,
                                      const Key& key,
                                      const shading::PanelPose& pose,
                                      const PixelRect& rect)
{
    drawSlice(programs, slot.buffer, pose, {0, 1, rect, interiorOf(key), key.width, key.height});
    slot.key = key;
    slot.bands = slot.slices = 1;
    slot.used = updates_;
    ++refreshes_;
    if (diffuseNodes_.x > 0) {
        // The diffuse grid now holds this pose's: a refresh's bands drawn with another's are
        // of no use (the next band asked for draws them again).
        for (Slot& s : slots_) {
            if (s.key && s.bands < s.slices) {
                s.key.reset();
            }
        }
    }
}

void BoothDiffuseCache::updateNodes(const BoothPrograms& programs,
                                    const CacheWant& want,
                                    const SurfaceLayout& layout,
                                    const PixelRect& rect)
{
    ++updates_;
    const Key frameKey = keyOf(want.shown, layout, width_, height_);
    const auto whole = [](const Slot* s) { return s != nullptr && s->bands == s->slices; };
    const auto held = [&](const shading::PanelPose& pose) -> Slot& {
        const Key key = keyOf(pose, layout, width_, height_);
        Slot* s = findSlot(key);
        if (whole(s)) {
            s->used = updates_;
            return *s;
        }
        if (s != nullptr) {
            s->key.reset(); // part of a refresh: drawn whole instead
        }
        Slot& slot = freeSlot(frameKey);
        drawNodeWhole(programs, slot, key, pose, rect);
        return slot;
    };
    // The band of a node drawn in bands. A last band goes first, since the frame may show the
    // node it completes; another after the terms shown, since a term drawn whole where a
    // diffuse grid is drawn forgets the bands drawn with another pose's grid.
    const auto drawBand = [&] {
        if (!want.band) {
            return;
        }
        const CacheBand& band = *want.band;
        const Key toward = keyOf(band.toward, layout, width_, height_);
        Slot* t = findSlot(toward);
        if (t == nullptr || (!whole(t) && (t->slices != band.bands || t->bands != band.band))) {
            // Not held, or not the bands before this one (a fresh cache, frame N drawn alone):
            // those bands first. Band by band, the pixels a whole draw makes.
            t = t != nullptr ? t : &freeSlot(frameKey);
            t->key = toward;
            t->slices = band.bands;
            for (int b = 0; b < band.band; ++b) {
                drawSlice(programs, t->buffer, band.toward,
                          {b, band.bands, rect, interiorOf(toward), width_, height_});
            }
            t->bands = band.band;
        }
        if (!whole(t)) {
            drawSlice(programs, t->buffer, band.toward,
                      {band.band, band.bands, rect, interiorOf(toward), width_, height_});
            if (++t->bands == t->slices) {
                ++refreshes_;
            }
        }
        t->used = updates_;
    };
    const bool lastBand = want.band && want.band->band + 1 >= want.band->bands;
    if (lastBand) {
        drawBand();
    }
    Slot& a = held(want.shown);
    Slot* const b = want.mixWith && want.mix > 0.0 ? &held(*want.mixWith) : nullptr;
    if (!lastBand) {
        drawBand();
    }
    if (b == nullptr) {
        frontBuffer_ = &a.buffer;
        return;
    }
    const MixKey mk{*a.key, *b->key, static_cast<float>(want.mix)};
    if (!mixedFor_ || !(*mixedFor_ == mk)) {
        if (!mixed_.texture) {
            makeBuffer(mixed_, false);
        }
        // Every pixel: around the surface the interpolated E_geo (the surround's light) as well.
        glBindFramebuffer(GL_FRAMEBUFFER, mixed_.fbo.get());
        glUseProgram(mixProgram_.get());
        glUniform1f(mixLocation_, mk.mix);
        glActiveTexture(GL_TEXTURE0 + kUnitCache);
        glBindTexture(GL_TEXTURE_2D, a.buffer.texture.get());
        glActiveTexture(GL_TEXTURE0 + kUnitCacheMix);
        glBindTexture(GL_TEXTURE_2D, b->buffer.texture.get());
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindTexture(GL_TEXTURE_2D, 0);
        glActiveTexture(GL_TEXTURE0 + kUnitCache);
        glBindTexture(GL_TEXTURE_2D, 0);
        glActiveTexture(GL_TEXTURE0);
        mixedFor_ = mk;
    }
    frontBuffer_ = &mixed_;
}

} // namespace replica::pipeline::render
