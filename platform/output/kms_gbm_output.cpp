// The KMS output's normal path: EGL on a GBM surface of the card. The renderer draws into its own
// framebuffers in that context; present() copies the finished frame on the GPU into the surface
// (glBlitFramebuffer), swaps, locks the front buffer and flips to it. No read-back.
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fmt/format.h>
#include <gbm.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <platform/output/egl_util.h>
#include <platform/output/kms_scanout.h>

namespace replica::platform {
namespace {

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

} // namespace

Expected<std::unique_ptr<Output>> createGbmKmsOutput(std::shared_ptr<KmsScanout> scanout)
{
    auto gbm = std::make_unique<GbmKmsOutput>(std::move(scanout));
    if (auto ok = gbm->init(); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::unique_ptr<Output>(std::move(gbm));
}

} // namespace replica::platform
