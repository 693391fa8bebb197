// The KMS output's fallback where the card has no GBM/EGL driver: a surfaceless context whose
// frames are read back and copied into double-buffered dumb buffers (scanout_copy.h).
#include <cerrno>
#include <cstring>
#include <memory>

#include <fmt/format.h>
#include <sys/mman.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <platform/output/kms_scanout.h>
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

Expected<std::unique_ptr<Output>> createDumbKmsOutput(std::shared_ptr<KmsScanout> scanout)
{
    std::uint64_t dumb = 0;
    if (drmGetCap(scanout->fd(), DRM_CAP_DUMB_BUFFER, &dumb) != 0 || dumb == 0) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("{} cannot scan out dumb buffers; use another card",
                                     scanout->device()));
    }
    auto gl = createHeadlessOutput();
    if (!gl) {
        return tl::unexpected(gl.error());
    }
    auto out = std::make_unique<DumbKmsOutput>(std::move(*gl), std::move(scanout));
    if (auto ok = out->init(); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::unique_ptr<Output>(std::move(out));
}

} // namespace replica::platform
