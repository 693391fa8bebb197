// Atomic KMS modesetting: the connector, the CRTC's mode and its primary plane in one commit for
// the first frame, the plane's framebuffer alone (non-blocking, with a flip event) for each later
// one.
#include <array>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <xf86drm.h>

#include <platform/output/kms_modeset.h>

namespace replica::platform {
namespace {

class AtomicModeset final : public KmsModeset
{
public:
    explicit AtomicModeset(const KmsPipe& pipe) : pipe_(pipe) {}
    ~AtomicModeset() override
    {
        if (modeBlob_ != 0) {
            drmModeDestroyPropertyBlob(pipe_.fd, modeBlob_);
        }
    }
    AtomicModeset(const AtomicModeset&) = delete;
    AtomicModeset& operator=(const AtomicModeset&) = delete;

    // Finds the CRTC's primary plane and the properties a commit sets; false with 'why' where one
    // is missing.
    bool init(std::string& why)
    {
        const int fd = pipe_.fd;
        if (drmSetClientCap(fd, DRM_CLIENT_CAP_UNIVERSAL_PLANES, 1) != 0 ||
            drmSetClientCap(fd, DRM_CLIENT_CAP_ATOMIC, 1) != 0) {
            why = "the driver offers no atomic API";
            return false;
        }
        planeId_ = primaryPlane();
        if (planeId_ == 0) {
            why = "no primary plane for the CRTC";
            return false;
        }
        const auto conn = DRM_MODE_OBJECT_CONNECTOR;
        const auto crtc = DRM_MODE_OBJECT_CRTC;
        const auto plane = DRM_MODE_OBJECT_PLANE;
        props_ = {propertyId(fd, pipe_.connectorId, conn, "CRTC_ID"),
                  propertyId(fd, pipe_.crtcId, crtc, "MODE_ID"),
                  propertyId(fd, pipe_.crtcId, crtc, "ACTIVE"),
                  propertyId(fd, planeId_, plane, "FB_ID"),
                  propertyId(fd, planeId_, plane, "CRTC_ID"),
                  propertyId(fd, planeId_, plane, "SRC_X"),
                  propertyId(fd, planeId_, plane, "SRC_Y"),
                  propertyId(fd, planeId_, plane, "SRC_W"),
                  propertyId(fd, planeId_, plane, "SRC_H"),
                  propertyId(fd, planeId_, plane, "CRTC_X"),
                  propertyId(fd, planeId_, plane, "CRTC_Y"),
                  propertyId(fd, planeId_, plane, "CRTC_W"),
                  propertyId(fd, planeId_, plane, "CRTC_H")};
        for (const std::uint32_t id : props_) {
            if (id == 0) {
                why = "a connector, CRTC or plane property is missing";
                return false;
            }
        }
        if (drmModeCreatePropertyBlob(fd, &pipe_.mode, sizeof(pipe_.mode), &modeBlob_) != 0) {
            why = fmt::format("cannot create a mode blob: {}", std::strerror(errno));
            return false;
        }
        return true;
    }

    bool atomic() const override { return true; }

    Expected<void> setMode(std::uint32_t fb) override
    {
        return commit(fb, DRM_MODE_ATOMIC_ALLOW_MODESET, nullptr);
    }

    Expected<void> flip(std::uint32_t fb, void* eventData) override
    {
        return commit(fb, DRM_MODE_PAGE_FLIP_EVENT | DRM_MODE_ATOMIC_NONBLOCK, eventData);
    }

private:
    // The CRTC's primary plane, 0 when there is none.
    std::uint32_t primaryPlane() const
    {
        std::uint32_t id = 0;
        drmModePlaneRes* planes = drmModeGetPlaneResources(pipe_.fd);
        if (planes == nullptr) {
            return 0;
        }
        for (std::uint32_t i = 0; i < planes->count_planes && id == 0; ++i) {
            drmModePlane* p = drmModeGetPlane(pipe_.fd, planes->planes[i]);
            if (p == nullptr) {
                continue;
            }
            const auto type = propertyValue(pipe_.fd, p->plane_id, DRM_MODE_OBJECT_PLANE, "type");
            if ((p->possible_crtcs & (1u << pipe_.crtcIndex)) != 0 && type &&
                *type == DRM_PLANE_TYPE_PRIMARY) {
                id = p->plane_id;
            }
            drmModeFreePlane(p);
        }
        drmModeFreePlaneResources(planes);
        return id;
    }

    Expected<void> commit(std::uint32_t fb, std::uint32_t flags, void* eventData)
    {
        drmModeAtomicReq* req = drmModeAtomicAlloc();
        if (req == nullptr) {
            return makeError(ErrorCode::Io, "out of memory for an atomic request");
        }
        const std::uint32_t w = pipe_.mode.hdisplay;
        const std::uint32_t h = pipe_.mode.vdisplay;
        const std::uint32_t crtcId = pipe_.crtcId;
        if ((flags & DRM_MODE_ATOMIC_ALLOW_MODESET) != 0) {
            drmModeAtomicAddProperty(req, pipe_.connectorId, props_[0], crtcId);
            drmModeAtomicAddProperty(req, crtcId, props_[1], modeBlob_);
            drmModeAtomicAddProperty(req, crtcId, props_[2], 1);
            drmModeAtomicAddProperty(req, planeId_, props_[4], crtcId);
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
        const int rc = drmModeAtomicCommit(pipe_.fd, req, flags, eventData);
        const int err = errno;
        drmModeAtomicFree(req);
        if (rc != 0) {
            return makeError(ErrorCode::Io,
                             fmt::format("{}: atomic commit on {} failed: {}", pipe_.device,
                                         pipe_.label, std::strerror(err)));
        }
        return {};
    }

    const KmsPipe& pipe_;
    std::uint32_t planeId_ = 0;
    std::array<std::uint32_t, 13> props_{};
    std::uint32_t modeBlob_ = 0;
};

} // namespace

std::unique_ptr<KmsModeset> createAtomicModeset(const KmsPipe& pipe, std::string& why)
{
    auto modeset = std::make_unique<AtomicModeset>(pipe);
    if (!modeset->init(why)) {
        return nullptr;
    }
    return modeset;
}

} // namespace replica::platform
