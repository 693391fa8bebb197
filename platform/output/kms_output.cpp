// KMS output: the appliance's fullscreen path on a console with no display server.
//
// KmsScanout picks the connector, its mode and a CRTC (and with atomic modesetting the CRTC's
// primary plane), sets the mode with the first frame and page-flips each later one on vertical
// blank, waiting for the flip's event so that the buffer drawn next is no longer on screen.
// Two ways to get frames into scan-out buffers sit on it:
//  - GbmKmsOutput (the normal path): EGL on a GBM surface of the card; the renderer draws into
//    its own framebuffers in that context, present() copies the finished frame on the GPU into the
//    surface (glBlitFramebuffer), swaps, locks the front buffer and flips to it. No read-back.
//  - DumbKmsOutput (the fallback where the card has no GBM/EGL driver): a surfaceless context
//    whose frames are read back and copied into double-buffered dumb buffers (scanout_copy.h).
#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <memory>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <gbm.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <platform/logging.h>
#include <platform/output/egl_util.h>
#include <platform/output/output.h>
#include <platform/output/scanout_copy.h>

namespace replica::platform {
namespace {

std::string envOr(const char* name, const std::string& fallback)
{
    const char* v = std::getenv(name);
    return v != nullptr && *v != '\0' ? std::string(v) : fallback;
}

// The id of the property 'name' of a KMS object, 0 when it has none.
std::uint32_t propertyId(int fd, std::uint32_t object, std::uint32_t type, const char* name)
{
    drmModeObjectProperties* props = drmModeObjectGetProperties(fd, object, type);
    if (props == nullptr) {
        return 0;
    }
    std::uint32_t id = 0;
    for (std::uint32_t i = 0; i < props->count_props && id == 0; ++i) {
        drmModePropertyRes* p = drmModeGetProperty(fd, props->props[i]);
        if (p != nullptr) {
            if (std::strcmp(p->name, name) == 0) {
                id = p->prop_id;
            }
            drmModeFreeProperty(p);
        }
    }
    drmModeFreeObjectProperties(props);
    return id;
}

// The value of the property 'name', when the object has it.
std::optional<std::uint64_t>
propertyValue(int fd, std::uint32_t object, std::uint32_t type, const char* name)
{
    drmModeObjectProperties* props = drmModeObjectGetProperties(fd, object, type);
    if (props == nullptr) {
        return std::nullopt;
    }
    std::optional<std::uint64_t> value;
    for (std::uint32_t i = 0; i < props->count_props && !value; ++i) {
        drmModePropertyRes* p = drmModeGetProperty(fd, props->props[i]);
        if (p != nullptr) {
            if (std::strcmp(p->name, name) == 0) {
                value = props->prop_values[i];
            }
            drmModeFreeProperty(p);
        }
    }
    drmModeFreeObjectProperties(props);
    return value;
}

// The physical size in the connector's EDID blob, else what the kernel took from it.
std::optional<SizeMm> connectorPhysicalSize(int fd, const drmModeConnector& c)
{
    if (auto blobId = propertyValue(fd, c.connector_id, DRM_MODE_OBJECT_CONNECTOR, "EDID");
        blobId && *blobId != 0) {
        drmModePropertyBlobRes* blob =
                drmModeGetPropertyBlob(fd, static_cast<std::uint32_t>(*blobId));
        if (blob != nullptr) {
            auto size =
                    edidPhysicalSize({static_cast<const std::uint8_t*>(blob->data), blob->length});
            drmModeFreePropertyBlob(blob);
            if (size) {
                return size;
            }
        }
    }
    if (c.mmWidth > 0 && c.mmHeight > 0) {
        return SizeMm{static_cast<double>(c.mmWidth), static_cast<double>(c.mmHeight)};
    }
    return std::nullopt;
}

class KmsScanout
{
public:
    KmsScanout(int fd, std::string device) : fd_(fd), device_(std::move(device)) {}
    ~KmsScanout()
    {
        restore();
        if (saved_ != nullptr) {
            drmModeFreeCrtc(saved_);
        }
        if (modeBlob_ != 0) {
            drmModeDestroyPropertyBlob(fd_, modeBlob_);
        }
        close(fd_);
    }
    KmsScanout(const KmsScanout&) = delete;
    KmsScanout& operator=(const KmsScanout&) = delete;

    Expected<void> init(const KmsOptions& o)
    {
        auto request = parseModeRequest(o.mode);
        if (!request) {
            return tl::unexpected(request.error());
        }
        drmModeRes* res = drmModeGetResources(fd_);
        if (res == nullptr) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("{} has no KMS resources (a render-only node?); use "
                                         "/dev/dri/cardN",
                                         device_));
        }
        drmModeConnector* chosen = nullptr;
        std::string seen;
        for (int i = 0; i < res->count_connectors && chosen == nullptr; ++i) {
            drmModeConnector* c = drmModeGetConnector(fd_, res->connectors[i]);
            if (c == nullptr) {
                continue;
            }
            const char* type = drmModeGetConnectorTypeName(c->connector_type);
            const std::string name =
                    fmt::format("{}-{}", type != nullptr ? type : "unknown", c->connector_type_id);
            seen += (seen.empty() ? "" : ", ") + name +
                    (c->connection == DRM_MODE_CONNECTED ? " (connected)" : "");
            if (c->connection == DRM_MODE_CONNECTED && c->count_modes > 0 &&
                (o.connector.empty() || o.connector == name)) {
                chosen = c;
                label_ = name;
            } else {
                drmModeFreeConnector(c);
            }
        }
        if (chosen == nullptr) {
            drmModeFreeResources(res);
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: no connected display{} (connectors: {}); check the "
                                         "cable and that the panel is on",
                                         device_, o.connector.empty() ? "" : " on " + o.connector,
                                         seen.empty() ? "none" : seen));
        }
        std::vector<DisplayMode> modes;
        for (int m = 0; m < chosen->count_modes; ++m) {
            const drmModeModeInfo& k = chosen->modes[m];
            modes.push_back({k.hdisplay, k.vdisplay, static_cast<int>(k.vrefresh),
                             (k.type & DRM_MODE_TYPE_PREFERRED) != 0});
        }
        auto index = chooseMode(modes, *request);
        if (!index && o.modeOrPreferred) {
            logger("output")->info("kms {} {}: no mode {}; taking the preferred one", device_,
                                   label_, o.mode);
            index = chooseMode(modes, ModeRequest{});
        }
        if (!index) {
            drmModeFreeConnector(chosen);
            drmModeFreeResources(res);
            return makeError(index.error().code,
                             fmt::format("{} {}: {}", device_, label_, index.error().message));
        }
        mode_ = chosen->modes[*index];
        connectorId_ = chosen->connector_id;
        edid_ = connectorPhysicalSize(fd_, *chosen);
        // A CRTC that one of the connector's encoders can drive.
        for (int e = 0; e < chosen->count_encoders && crtcId_ == 0; ++e) {
            drmModeEncoder* enc = drmModeGetEncoder(fd_, chosen->encoders[e]);
            if (enc == nullptr) {
                continue;
            }
            for (int c = 0; c < res->count_crtcs; ++c) {
                if ((enc->possible_crtcs & (1u << c)) != 0) {
                    crtcId_ = res->crtcs[c];
                    crtcIndex_ = c;
                    break;
                }
            }
            drmModeFreeEncoder(enc);
        }
        drmModeFreeConnector(chosen);
        drmModeFreeResources(res);
        if (crtcId_ == 0) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("{}: no CRTC can drive {}", device_, label_));
        }
        saved_ = drmModeGetCrtc(fd_, crtcId_);
        const std::string modeset = envOr("REPLICA_KMS_MODESET", o.modeset);
        if (modeset != "auto" && modeset != "atomic" && modeset != "legacy") {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("KMS modeset '{}': expected auto, atomic or legacy", modeset));
        }
        if (modeset != "legacy") {
            std::string why;
            atomic_ = setUpAtomic(why);
            if (!atomic_) {
                if (modeset == "atomic") {
                    return makeError(ErrorCode::Unsupported,
                                     fmt::format("{}: no atomic modesetting ({})", device_, why));
                }
                logger("output")->info("kms {}: legacy modesetting ({})", device_, why);
            }
        }
        return {};
    }

    // Shows framebuffer fb: the first call sets the mode, later ones flip on vertical blank and
    // return once the flip has happened.
    Expected<void> show(std::uint32_t fb)
    {
        if (!modeSet_) {
            if (atomic_) {
                if (auto ok = commitAtomic(fb, DRM_MODE_ATOMIC_ALLOW_MODESET); ok) {
                    modeSet_ = true;
                    logger("output")->info("kms {}: first frame on screen", describe());
                    return {};
                } else {
                    // A driver that lists the properties but refuses the commit: legacy calls.
                    logger("output")->warn("kms {}: atomic modeset failed ({}); using legacy "
                                           "modesetting",
                                           device_, ok.error().message);
                    atomic_ = false;
                }
            }
            if (drmModeSetCrtc(fd_, crtcId_, fb, 0, 0, &connectorId_, 1, &mode_) != 0) {
                return makeError(ErrorCode::Io,
                                 fmt::format("{}: cannot set mode {}x{} on {}: {}; is a display "
                                             "server running (stop it, or use --output headless)?",
                                             device_, mode_.hdisplay, mode_.vdisplay, label_,
                                             std::strerror(errno)));
            }
            modeSet_ = true;
            logger("output")->info("kms {}: first frame on screen", describe());
            return {};
        }
        flipped_ = false;
        if (atomic_) {
            if (auto ok = commitAtomic(fb, DRM_MODE_PAGE_FLIP_EVENT | DRM_MODE_ATOMIC_NONBLOCK);
                !ok) {
                return ok;
            }
        } else if (drmModePageFlip(fd_, crtcId_, fb, DRM_MODE_PAGE_FLIP_EVENT, this) != 0) {
            return makeError(ErrorCode::Io, fmt::format("{}: page flip failed: {}", device_,
                                                        std::strerror(errno)));
        }
        drmEventContext ev{};
        ev.version = 2;
        ev.page_flip_handler = [](int, unsigned, unsigned, unsigned, void* self) {
            static_cast<KmsScanout*>(self)->flipped_ = true;
        };
        // A display refreshes at least every 100 ms; a second without the event is a fault.
        for (int waited = 0; !flipped_ && waited < 1000; waited += 100) {
            pollfd p{fd_, POLLIN, 0};
            if (poll(&p, 1, 100) > 0) {
                drmHandleEvent(fd_, &ev);
            }
        }
        if (!flipped_) {
            return makeError(ErrorCode::DeviceFailure,
                             fmt::format("{}: page flip on {} did not complete within 1 s", device_,
                                         label_));
        }
        return {};
    }

    // Puts back what the CRTC showed before (the console) once a frame has been shown.
    void restore()
    {
        if (saved_ != nullptr && modeSet_ && saved_->buffer_id != 0) {
            drmModeSetCrtc(fd_, saved_->crtc_id, saved_->buffer_id, saved_->x, saved_->y,
                           &connectorId_, 1, &saved_->mode);
        }
        modeSet_ = false;
    }

    int fd() const { return fd_; }
    const std::string& device() const { return device_; }
    int width() const { return mode_.hdisplay; }
    int height() const { return mode_.vdisplay; }
    DisplayInfo info() const { return {mode_.hdisplay, mode_.vdisplay, edid_, label_}; }
    std::string describe() const
    {
        return fmt::format("{} {} {}x{}@{} {}", device_, label_, mode_.hdisplay, mode_.vdisplay,
                           mode_.vrefresh, atomic_ ? "atomic" : "legacy");
    }

private:
    bool setUpAtomic(std::string& why)
    {
        if (drmSetClientCap(fd_, DRM_CLIENT_CAP_UNIVERSAL_PLANES, 1) != 0 ||
            drmSetClientCap(fd_, DRM_CLIENT_CAP_ATOMIC, 1) != 0) {
            why = "the driver offers no atomic API";
            return false;
        }
        drmModePlaneRes* planes = drmModeGetPlaneResources(fd_);
        if (planes != nullptr) {
            for (std::uint32_t i = 0; i < planes->count_planes && planeId_ == 0; ++i) {
                drmModePlane* p = drmModeGetPlane(fd_, planes->planes[i]);
                if (p == nullptr) {
                    continue;
                }
                const auto type = propertyValue(fd_, p->plane_id, DRM_MODE_OBJECT_PLANE, "type");
                if ((p->possible_crtcs & (1u << crtcIndex_)) != 0 && type &&
                    *type == DRM_PLANE_TYPE_PRIMARY) {
                    planeId_ = p->plane_id;
                }
                drmModeFreePlane(p);
            }
            drmModeFreePlaneResources(planes);
        }
        if (planeId_ == 0) {
            why = "no primary plane for the CRTC";
            return false;
        }
        const auto conn = DRM_MODE_OBJECT_CONNECTOR;
        const auto crtc = DRM_MODE_OBJECT_CRTC;
        const auto plane = DRM_MODE_OBJECT_PLANE;
        props_ = {propertyId(fd_, connectorId_, conn, "CRTC_ID"),
                  propertyId(fd_, crtcId_, crtc, "MODE_ID"),
                  propertyId(fd_, crtcId_, crtc, "ACTIVE"),
                  propertyId(fd_, planeId_, plane, "FB_ID"),
                  propertyId(fd_, planeId_, plane, "CRTC_ID"),
                  propertyId(fd_, planeId_, plane, "SRC_X"),
                  propertyId(fd_, planeId_, plane, "SRC_Y"),
                  propertyId(fd_, planeId_, plane, "SRC_W"),
                  propertyId(fd_, planeId_, plane, "SRC_H"),
                  propertyId(fd_, planeId_, plane, "CRTC_X"),
                  propertyId(fd_, planeId_, plane, "CRTC_Y"),
                  propertyId(fd_, planeId_, plane, "CRTC_W"),
                  propertyId(fd_, planeId_, plane, "CRTC_H")};
        for (const std::uint32_t id : props_) {
            if (id == 0) {
                why = "a connector, CRTC or plane property is missing";
                return false;
            }
        }
        if (drmModeCreatePropertyBlob(fd_, &mode_, sizeof(mode_), &modeBlob_) != 0) {
            why = fmt::format("cannot create a mode blob: {}", std::strerror(errno));
            return false;
        }
        return true;
    }

    Expected<void> commitAtomic(std::uint32_t fb, std::uint32_t flags)
    {
        drmModeAtomicReq* req = drmModeAtomicAlloc();
        if (req == nullptr) {
            return makeError(ErrorCode::Io, "out of memory for an atomic request");
        }
        const std::uint32_t w = mode_.hdisplay;
        const std::uint32_t h = mode_.vdisplay;
        if ((flags & DRM_MODE_ATOMIC_ALLOW_MODESET) != 0) {
            drmModeAtomicAddProperty(req, connectorId_, props_[0], crtcId_);
            drmModeAtomicAddProperty(req, crtcId_, props_[1], modeBlob_);
            drmModeAtomicAddProperty(req, crtcId_, props_[2], 1);
            drmModeAtomicAddProperty(req, planeId_, props_[4], crtcId_);
            drmModeAtomicAddProperty(req, planeId_, props_[5], 0);
            drmModeAtomicAddProperty(req, planeId_, props_[6], 0);
            drmModeAtomicAddProperty(req, planeId_, props_[7], std::uint64_t{w} << 16);
            drmModeAtomicAddProperty(req, planeId_, props_[8], std::uint64_t{h} << 16);
            drmModeAtomicAddProperty(req, planeId_, props_[9], 0);
            drmModeAtomicAddProperty(req, planeId_, props_[10], 0);
            drmModeAtomicAddProperty(req, planeId_, props_[11], w);
            drmModeAtomicAddProperty(req, planeId_, props_[12], h);
        }
        drmModeAtomicAddProperty(req, planeId_, props_[3], fb);
        const int rc = drmModeAtomicCommit(fd_, req, flags, this);
        const int err = errno;
        drmModeAtomicFree(req);
        if (rc != 0) {
            return makeError(ErrorCode::Io, fmt::format("{}: atomic commit on {} failed: {}",
                                                        device_, label_, std::strerror(err)));
        }
        return {};
    }

    int fd_;
    std::string device_;
    std::string label_;
    drmModeModeInfo mode_{};
    std::optional<SizeMm> edid_;
    std::uint32_t connectorId_ = 0;
    std::uint32_t crtcId_ = 0;
    int crtcIndex_ = 0;
    std::uint32_t planeId_ = 0;
    bool atomic_ = false;
    std::array<std::uint32_t, 13> props_{};
    std::uint32_t modeBlob_ = 0;
    drmModeCrtc* saved_ = nullptr;
    bool modeSet_ = false;
    bool flipped_ = false;
};

// A KMS framebuffer for a GBM buffer, made once and removed when GBM destroys the buffer.
struct BoFramebuffer {
    int fd = -1;
    std::uint32_t id = 0;
};

class GbmKmsOutput final : public Output
{
public:
    explicit GbmKmsOutput(std::shared_ptr<KmsScanout> scanout) : scanout_(std::move(scanout)) {}
    ~GbmKmsOutput() override
    {
        // The console back before the buffers it would otherwise show go.
        scanout_->restore();
        if (display_ != EGL_NO_DISPLAY) {
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            if (surface_ != EGL_NO_SURFACE) {
                eglDestroySurface(display_, surface_);
            }
            if (context_ != EGL_NO_CONTEXT) {
                eglDestroyContext(display_, context_);
            }
            eglTerminate(display_);
        }
        if (gbmSurface_ != nullptr) {
            if (front_ != nullptr) {
                gbm_surface_release_buffer(gbmSurface_, front_);
            }
            gbm_surface_destroy(gbmSurface_);
        }
        if (gbm_ != nullptr) {
            gbm_device_destroy(gbm_);
        }
    }
    GbmKmsOutput(const GbmKmsOutput&) = delete;
    GbmKmsOutput& operator=(const GbmKmsOutput&) = delete;

    Expected<void> init()
    {
        const std::string& dev = scanout_->device();
        gbm_ = gbm_create_device(scanout_->fd());
        if (gbm_ == nullptr) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("gbm_create_device({}) failed", dev));
        }
        const auto w = static_cast<std::uint32_t>(scanout_->width());
        const auto h = static_cast<std::uint32_t>(scanout_->height());
        gbmSurface_ = gbm_surface_create(gbm_, w, h, GBM_FORMAT_XRGB8888,
                                         GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
        if (gbmSurface_ == nullptr) {
            return makeError(
                    ErrorCode::Unsupported,
                    fmt::format("{}: no {}x{} XRGB8888 GBM surface for scan-out", dev, w, h));
        }
        const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
        auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
                eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (getPlatformDisplay == nullptr || (!hasExtension(clientExts, "EGL_KHR_platform_gbm") &&
                                              !hasExtension(clientExts, "EGL_MESA_platform_gbm"))) {
            return makeError(ErrorCode::Unsupported, "EGL has no GBM platform");
        }
        display_ = getPlatformDisplay(EGL_PLATFORM_GBM_KHR, gbm_, nullptr);
        if (display_ == EGL_NO_DISPLAY || eglInitialize(display_, nullptr, nullptr) != EGL_TRUE) {
            const std::string err = eglErrorString();
            display_ = EGL_NO_DISPLAY;
            return makeError(ErrorCode::Unsupported,
                             fmt::format("EGL on GBM of {} does not initialise ({})", dev, err));
        }
        if (eglBindAPI(EGL_OPENGL_ES_API) != EGL_TRUE) {
            return makeError(ErrorCode::Unsupported, "EGL on GBM cannot bind OpenGL ES");
        }
        const EGLint want[] = {EGL_SURFACE_TYPE,
                               EGL_WINDOW_BIT,
                               EGL_RED_SIZE,
                               8,
                               EGL_GREEN_SIZE,
                               8,
                               EGL_BLUE_SIZE,
                               8,
                               EGL_RENDERABLE_TYPE,
                               EGL_OPENGL_ES3_BIT,
                               EGL_NONE};
        EGLConfig configs[64];
        EGLint count = 0;
        eglChooseConfig(display_, want, configs, 64, &count);
        EGLConfig config = nullptr;
        for (EGLint i = 0; i < count && config == nullptr; ++i) {
            EGLint visual = 0;
            if (eglGetConfigAttrib(display_, configs[i], EGL_NATIVE_VISUAL_ID, &visual) ==
                        EGL_TRUE &&
                static_cast<std::uint32_t>(visual) == GBM_FORMAT_XRGB8888) {
                config = configs[i];
            }
        }
        if (config == nullptr) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("EGL on GBM of {}: no GLES 3 window config in "
                                         "XRGB8888 ({} candidates)",
                                         dev, count));
        }
        const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 1,
                                         EGL_NONE};
        context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, contextAttribs);
        if (context_ == EGL_NO_CONTEXT) {
            return makeError(
                    ErrorCode::Unsupported,
                    fmt::format("EGL on GBM: no OpenGL ES 3.1 context ({})", eglErrorString()));
        }
        surface_ = eglCreateWindowSurface(
                display_, config, reinterpret_cast<EGLNativeWindowType>(gbmSurface_), nullptr);
        if (surface_ == EGL_NO_SURFACE) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("EGL on GBM: no window surface ({})", eglErrorString()));
        }
        if (eglMakeCurrent(display_, surface_, surface_, context_) != EGL_TRUE) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("EGL on GBM: cannot make the context current ({})",
                                         eglErrorString()));
        }
        // Swaps wait for nothing: the page flip is the pacing.
        eglSwapInterval(display_, 0);
        return {};
    }

    std::string name() const override { return "kms " + scanout_->describe() + " gbm"; }
    std::string glRenderer() const override
    {
        const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        return r != nullptr ? r : "unknown";
    }
    std::optional<DisplayInfo> display() const override { return scanout_->info(); }

    Expected<void> present(const DisplayFrame& frame) override
    {
        if (frame.glFramebuffer == 0) {
            return makeError(ErrorCode::InvalidArgument,
                             "kms (gbm): the frame has no framebuffer to copy from");
        }
        const int mw = scanout_->width();
        const int mh = scanout_->height();
        // Centred; cropped where the frame is larger than the mode.
        const int cw = std::min(frame.width, mw);
        const int ch = std::min(frame.height, mh);
        const int sx = (frame.width - cw) / 2;
        const int sy = (frame.height - ch) / 2;
        const int dx = (mw - cw) / 2;
        const int dy = (mh - ch) / 2;
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        if (cw != mw || ch != mh) {
            glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
            glClear(GL_COLOR_BUFFER_BIT);
        }
        glBindFramebuffer(GL_READ_FRAMEBUFFER, frame.glFramebuffer);
        glBlitFramebuffer(sx, sy, sx + cw, sy + ch, dx, dy, dx + cw, dy + ch, GL_COLOR_BUFFER_BIT,
                          GL_NEAREST);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        if (eglSwapBuffers(display_, surface_) != EGL_TRUE) {
            return makeError(
                    ErrorCode::DeviceFailure,
                    fmt::format("kms (gbm): eglSwapBuffers failed ({})", eglErrorString()));
        }
        gbm_bo* bo = gbm_surface_lock_front_buffer(gbmSurface_);
        if (bo == nullptr) {
            return makeError(ErrorCode::DeviceFailure, "kms (gbm): no front buffer after a swap");
        }
        auto fb = framebufferFor(bo);
        if (!fb) {
            gbm_surface_release_buffer(gbmSurface_, bo);
            return tl::unexpected(fb.error());
        }
        if (auto ok = scanout_->show(*fb); !ok) {
            gbm_surface_release_buffer(gbmSurface_, bo);
            return ok;
        }
        // The buffer shown before is off screen now: GBM may draw into it again.
        if (front_ != nullptr) {
            gbm_surface_release_buffer(gbmSurface_, front_);
        }
        front_ = bo;
        return {};
    }

private:
    Expected<std::uint32_t> framebufferFor(gbm_bo* bo)
    {
        if (auto* known = static_cast<BoFramebuffer*>(gbm_bo_get_user_data(bo))) {
            return known->id;
        }
        const std::uint32_t handles[4] = {gbm_bo_get_handle(bo).u32, 0, 0, 0};
        const std::uint32_t pitches[4] = {gbm_bo_get_stride(bo), 0, 0, 0};
        const std::uint32_t offsets[4] = {0, 0, 0, 0};
        std::uint32_t id = 0;
        if (drmModeAddFB2(scanout_->fd(), gbm_bo_get_width(bo), gbm_bo_get_height(bo),
                          GBM_FORMAT_XRGB8888, handles, pitches, offsets, &id, 0) != 0) {
            return makeError(ErrorCode::Io,
                             fmt::format("{}: cannot add a framebuffer for a GBM buffer: {}",
                                         scanout_->device(), std::strerror(errno)));
        }
        gbm_bo_set_user_data(bo, new BoFramebuffer{scanout_->fd(), id}, [](gbm_bo*, void* data) {
            auto* f = static_cast<BoFramebuffer*>(data);
            drmModeRmFB(f->fd, f->id);
            delete f;
        });
        return id;
    }

    std::shared_ptr<KmsScanout> scanout_; // outlives the GBM objects (it owns the card's fd)
    gbm_device* gbm_ = nullptr;
    gbm_surface* gbmSurface_ = nullptr;
    gbm_bo* front_ = nullptr; // on screen
    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    EGLSurface surface_ = EGL_NO_SURFACE;
};

struct DumbBuffer {
    std::uint32_t handle = 0;
    std::uint32_t fbId = 0;
    std::uint32_t pitch = 0;
    std::uint64_t size = 0;
    std::uint8_t* map = nullptr;
};

class DumbKmsOutput final : public Output
{
public:
    DumbKmsOutput(std::unique_ptr<Output> gl, std::shared_ptr<KmsScanout> scanout)
        : gl_(std::move(gl)), scanout_(std::move(scanout))
    {}

    ~DumbKmsOutput() override
    {
        scanout_->restore();
        const int fd = scanout_->fd();
        for (auto& b : buffers_) {
            if (b.map != nullptr) {
                munmap(b.map, b.size);
            }
            if (b.fbId != 0) {
                drmModeRmFB(fd, b.fbId);
            }
            if (b.handle != 0) {
                drm_mode_destroy_dumb d{};
                d.handle = b.handle;
                drmIoctl(fd, DRM_IOCTL_MODE_DESTROY_DUMB, &d);
            }
        }
    }
    DumbKmsOutput(const DumbKmsOutput&) = delete;
    DumbKmsOutput& operator=(const DumbKmsOutput&) = delete;

    Expected<void> init()
    {
        for (auto& b : buffers_) {
            if (auto ok = createBuffer(b); !ok) {
                return ok;
            }
        }
        return {};
    }

    std::string name() const override { return "kms " + scanout_->describe() + " dumb"; }
    std::string glRenderer() const override { return gl_->glRenderer(); }
    bool needsPixels() const override { return true; }
    std::optional<DisplayInfo> display() const override { return scanout_->info(); }

    Expected<void> present(const DisplayFrame& frame) override
    {
        DumbBuffer& back = buffers_[static_cast<std::size_t>(1 - front_)];
        copyToScanout(frame.width, frame.height, frame.rgba,
                      {scanout_->width(), scanout_->height(), back.pitch, {back.map, back.size}});
        if (auto ok = scanout_->show(back.fbId); !ok) {
            return ok;
        }
        front_ = 1 - front_;
        return {};
    }

private:
    Expected<void> createBuffer(DumbBuffer& b)
    {
        const int fd = scanout_->fd();
        const std::string& dev = scanout_->device();
        drm_mode_create_dumb create{};
        create.width = static_cast<std::uint32_t>(scanout_->width());
        create.height = static_cast<std::uint32_t>(scanout_->height());
        create.bpp = 32;
        if (drmIoctl(fd, DRM_IOCTL_MODE_CREATE_DUMB, &create) != 0) {
            return makeError(ErrorCode::Io,
                             fmt::format("{}: cannot create a {}x{} scan-out "
                                         "buffer: {}",
                                         dev, create.width, create.height, std::strerror(errno)));
        }
        b.handle = create.handle;
        b.pitch = create.pitch;
        b.size = create.size;
        if (drmModeAddFB(fd, create.width, create.height, 24, 32, b.pitch, b.handle, &b.fbId) !=
            0) {
            return makeError(ErrorCode::Io, fmt::format("{}: cannot add a framebuffer: {}", dev,
                                                        std::strerror(errno)));
        }
        drm_mode_map_dumb map{};
        map.handle = b.handle;
        if (drmIoctl(fd, DRM_IOCTL_MODE_MAP_DUMB, &map) != 0) {
            return makeError(ErrorCode::Io, fmt::format("{}: cannot map a scan-out buffer: {}", dev,
                                                        std::strerror(errno)));
        }
        void* m = mmap(nullptr, b.size, PROT_READ | PROT_WRITE, MAP_SHARED, fd,
                       static_cast<off_t>(map.offset));
        if (m == MAP_FAILED) {
            return makeError(ErrorCode::Io, fmt::format("{}: mmap of a scan-out buffer failed: {}",
                                                        dev, std::strerror(errno)));
        }
        b.map = static_cast<std::uint8_t*>(m);
        return {};
    }

    std::unique_ptr<Output> gl_; // the rendering context; frames arrive read back from it
    std::shared_ptr<KmsScanout> scanout_;
    DumbBuffer buffers_[2];
    int front_ = 0;
};

} // namespace

Expected<std::unique_ptr<Output>> createKmsOutput(const KmsOptions& options)
{
    const std::string& device = options.device;
    const int fd = open(device.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) {
        const int err = errno;
        return makeError(err == ENOENT ? ErrorCode::NotFound : ErrorCode::Io,
                         fmt::format("cannot open {}: {}; {}", device, std::strerror(err),
                                     err == ENOENT ? "this machine has no display device here "
                                                     "(use --output headless)"
                                                   : "add this user to the 'video' group"));
    }
    auto scanout = std::make_shared<KmsScanout>(fd, device);
    if (auto ok = scanout->init(options); !ok) {
        return tl::unexpected(ok.error());
    }
    const std::string path = envOr("REPLICA_KMS_PATH", options.path);
    if (path != "auto" && path != "gbm" && path != "dumb") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("KMS path '{}': expected auto, gbm or dumb", path));
    }
    auto log = logger("output");
    if (path != "dumb") {
        auto gbm = std::make_unique<GbmKmsOutput>(scanout);
        auto ok = gbm->init();
        if (ok) {
            log->info("kms: {}: EGL on a GBM surface, frames copied on the GPU and page-flipped",
                      scanout->describe());
            return std::unique_ptr<Output>(std::move(gbm));
        }
        if (path == "gbm") {
            return tl::unexpected(ok.error());
        }
        gbm.reset();
        log->warn("kms: {}; falling back to CPU copies into dumb buffers", ok.error().message);
    }
    std::uint64_t dumb = 0;
    if (drmGetCap(fd, DRM_CAP_DUMB_BUFFER, &dumb) != 0 || dumb == 0) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("{} cannot scan out dumb buffers; use another card", device));
    }
    auto gl = createHeadlessOutput();
    if (!gl) {
        return tl::unexpected(gl.error());
    }
    auto out = std::make_unique<DumbKmsOutput>(std::move(*gl), scanout);
    if (auto ok = out->init(); !ok) {
        return tl::unexpected(ok.error());
    }
    log->info("kms: {}: frames read back and copied into dumb buffers", scanout->describe());
    return std::unique_ptr<Output>(std::move(out));
}

} // namespace replica::platform
