// KMS output: the appliance's fullscreen path on a console with no display server. The renderer
// keeps its surfaceless EGL context; finished frames are copied into double-buffered DRM dumb
// buffers and shown with a page flip on vertical blank. Simple and driver-independent; a zero-copy
// GBM surface is the later optimisation (docs/architecture.md).
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <platform/output/output.h>
#include <platform/output/scanout_copy.h>

namespace replica::platform {
namespace {

struct DumbBuffer {
    std::uint32_t handle = 0;
    std::uint32_t fbId = 0;
    std::uint32_t pitch = 0;
    std::uint64_t size = 0;
    std::uint8_t* map = nullptr;
};

class KmsOutput final : public Output
{
public:
    KmsOutput(std::unique_ptr<Output> gl, int fd, std::string device)
        : gl_(std::move(gl)), fd_(fd), device_(std::move(device))
    {}

    ~KmsOutput() override
    {
        if (saved_ != nullptr) {
            drmModeSetCrtc(fd_, saved_->crtc_id, saved_->buffer_id, saved_->x, saved_->y,
                           &connectorId_, 1, &saved_->mode);
            drmModeFreeCrtc(saved_);
        }
        for (auto& b : buffers_) {
            if (b.map != nullptr) {
                munmap(b.map, b.size);
            }
            if (b.fbId != 0) {
                drmModeRmFB(fd_, b.fbId);
            }
            if (b.handle != 0) {
                drm_mode_destroy_dumb d{};
                d.handle = b.handle;
                drmIoctl(fd_, DRM_IOCTL_MODE_DESTROY_DUMB, &d);
            }
        }
        close(fd_);
    }
    KmsOutput(const KmsOutput&) = delete;
    KmsOutput& operator=(const KmsOutput&) = delete;

    Expected<void> init(const std::string& connectorName)
    {
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
            const std::string name =
                    fmt::format("{}-{}",
                                drmModeGetConnectorTypeName(c->connector_type) != nullptr
                                        ? drmModeGetConnectorTypeName(c->connector_type)
                                        : "unknown",
                                c->connector_type_id);
            seen += (seen.empty() ? "" : ", ") + name +
                    (c->connection == DRM_MODE_CONNECTED ? " (connected)" : "");
            if (c->connection == DRM_MODE_CONNECTED && c->count_modes > 0 &&
                (connectorName.empty() || connectorName == name)) {
                chosen = c;
                connectorLabel_ = name;
            } else {
                drmModeFreeConnector(c);
            }
        }
        if (chosen == nullptr) {
            drmModeFreeResources(res);
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: no connected display{} (connectors: {}); check the "
                                         "cable and that the panel is on",
                                         device_,
                                         connectorName.empty() ? "" : " on " + connectorName,
                                         seen.empty() ? "none" : seen));
        }
        mode_ = chosen->modes[0];
        for (int m = 0; m < chosen->count_modes; ++m) {
            if ((chosen->modes[m].type & DRM_MODE_TYPE_PREFERRED) != 0) {
                mode_ = chosen->modes[m];
                break;
            }
        }
        connectorId_ = chosen->connector_id;
        // A CRTC that one of the connector's encoders can drive.
        for (int e = 0; e < chosen->count_encoders && crtcId_ == 0; ++e) {
            drmModeEncoder* enc = drmModeGetEncoder(fd_, chosen->encoders[e]);
            if (enc == nullptr) {
                continue;
            }
            for (int c = 0; c < res->count_crtcs; ++c) {
                if ((enc->possible_crtcs & (1u << c)) != 0) {
                    crtcId_ = res->crtcs[c];
                    break;
                }
            }
            drmModeFreeEncoder(enc);
        }
        drmModeFreeConnector(chosen);
        drmModeFreeResources(res);
        if (crtcId_ == 0) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("{}: no CRTC can drive {}", device_, connectorLabel_));
        }
        for (auto& b : buffers_) {
            if (auto ok = createBuffer(b); !ok) {
                return ok;
            }
        }
        saved_ = drmModeGetCrtc(fd_, crtcId_);
        if (drmModeSetCrtc(fd_, crtcId_, buffers_[0].fbId, 0, 0, &connectorId_, 1, &mode_) != 0) {
            return makeError(ErrorCode::Io,
                             fmt::format("{}: cannot set mode {}x{} on {}: {}; is a display "
                                         "server running (stop it, or use --output headless)?",
                                         device_, mode_.hdisplay, mode_.vdisplay, connectorLabel_,
                                         std::strerror(errno)));
        }
        return {};
    }

    std::string name() const override
    {
        return fmt::format("kms {} {} {}x{}@{}", device_, connectorLabel_, mode_.hdisplay,
                           mode_.vdisplay, mode_.vrefresh);
    }
    std::string glRenderer() const override { return gl_->glRenderer(); }

    Expected<void> present(const DisplayFrame& frame) override
    {
        DumbBuffer& back = buffers_[static_cast<std::size_t>(1 - front_)];
        copyToScanout(frame.width, frame.height, frame.rgba,
                      {mode_.hdisplay, mode_.vdisplay, back.pitch, {back.map, back.size}});
        if (drmModePageFlip(fd_, crtcId_, back.fbId, DRM_MODE_PAGE_FLIP_EVENT, this) != 0) {
            return makeError(ErrorCode::Io, fmt::format("{}: page flip failed: {}", device_,
                                                        std::strerror(errno)));
        }
        // Wait for the flip so that the buffer we write next is no longer on screen.
        drmEventContext ev{};
        ev.version = 2;
        ev.page_flip_handler = [](int, unsigned, unsigned, unsigned, void*) {};
        pollfd p{fd_, POLLIN, 0};
        if (poll(&p, 1, 100) > 0) {
            drmHandleEvent(fd_, &ev);
        }
        front_ = 1 - front_;
        return {};
    }

private:
    Expected<void> createBuffer(DumbBuffer& b)
    {
        drm_mode_create_dumb create{};
        create.width = mode_.hdisplay;
        create.height = mode_.vdisplay;
        create.bpp = 32;
        if (drmIoctl(fd_, DRM_IOCTL_MODE_CREATE_DUMB, &create) != 0) {
            return makeError(ErrorCode::Io, fmt::format("{}: cannot create a {}x{} scan-out "
                                                        "buffer: {}",
                                                        device_, create.width, create.height,
                                                        std::strerror(errno)));
        }
        b.handle = create.handle;
        b.pitch = create.pitch;
        b.size = create.size;
        if (drmModeAddFB(fd_, create.width, create.height, 24, 32, b.pitch, b.handle, &b.fbId) !=
            0) {
            return makeError(ErrorCode::Io, fmt::format("{}: cannot add a framebuffer: {}", device_,
                                                        std::strerror(errno)));
        }
        drm_mode_map_dumb map{};
        map.handle = b.handle;
        if (drmIoctl(fd_, DRM_IOCTL_MODE_MAP_DUMB, &map) != 0) {
            return makeError(ErrorCode::Io, fmt::format("{}: cannot map a scan-out buffer: {}",
                                                        device_, std::strerror(errno)));
        }
        void* m = mmap(nullptr, b.size, PROT_READ | PROT_WRITE, MAP_SHARED, fd_,
                       static_cast<off_t>(map.offset));
        if (m == MAP_FAILED) {
            return makeError(ErrorCode::Io, fmt::format("{}: mmap of a scan-out buffer failed: {}",
                                                        device_, std::strerror(errno)));
        }
        b.map = static_cast<std::uint8_t*>(m);
        return {};
    }

    std::unique_ptr<Output> gl_; // the rendering context; frames arrive read back from it
    int fd_;
    std::string device_;
    std::string connectorLabel_;
    drmModeModeInfo mode_{};
    std::uint32_t connectorId_ = 0;
    std::uint32_t crtcId_ = 0;
    drmModeCrtc* saved_ = nullptr;
    DumbBuffer buffers_[2];
    int front_ = 0;
};

} // namespace

Expected<std::unique_ptr<Output>> createKmsOutput(const std::string& device,
                                                  const std::string& connector)
{
    const int fd = open(device.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) {
        const int err = errno;
        return makeError(err == ENOENT ? ErrorCode::NotFound : ErrorCode::Io,
                         fmt::format("cannot open {}: {}; {}", device, std::strerror(err),
                                     err == ENOENT ? "this machine has no display device here "
                                                     "(use --output headless)"
                                                   : "add this user to the 'video' group"));
    }
    std::uint64_t dumb = 0;
    if (drmGetCap(fd, DRM_CAP_DUMB_BUFFER, &dumb) != 0 || dumb == 0) {
        close(fd);
        return makeError(ErrorCode::Unsupported,
                         fmt::format("{} cannot scan out dumb buffers; use another card", device));
    }
    auto gl = createHeadlessOutput();
    if (!gl) {
        close(fd);
        return tl::unexpected(gl.error());
    }
    auto out = std::make_unique<KmsOutput>(std::move(*gl), fd, device);
    if (auto ok = out->init(connector); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::unique_ptr<Output>(std::move(out));
}

} // namespace replica::platform
