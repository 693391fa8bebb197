// Legacy KMS modesetting: drmModeSetCrtc for the mode, drmModePageFlip for each later frame.
#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <xf86drm.h>

#include <platform/output/kms_modeset.h>

namespace replica::platform {
namespace {

class LegacyModeset final : public KmsModeset
{
public:
    explicit LegacyModeset(const KmsPipe& pipe) : pipe_(pipe) {}

    bool atomic() const override { return false; }

    Expected<void> setMode(std::uint32_t fb) override
    {
        auto connector = pipe_.connectorId;
        auto mode = pipe_.mode;
        if (drmModeSetCrtc(pipe_.fd, pipe_.crtcId, fb, 0, 0, &connector, 1, &mode) != 0) {
            return makeError(ErrorCode::Io,
                             fmt::format("{}: cannot set mode {}x{} on {}: {}; is a display "
                                         "server running (stop it, or use --output headless)?",
                                         pipe_.device, pipe_.mode.hdisplay, pipe_.mode.vdisplay,
                                         pipe_.label, std::strerror(errno)));
        }
        return {};
    }

    Expected<void> flip(std::uint32_t fb, void* eventData) override
    {
        if (drmModePageFlip(pipe_.fd, pipe_.crtcId, fb, DRM_MODE_PAGE_FLIP_EVENT, eventData) != 0) {
            return makeError(ErrorCode::Io, fmt::format("{}: page flip failed: {}", pipe_.device,
                                                        std::strerror(errno)));
        }
        return {};
    }

private:
    const KmsPipe& pipe_;
};

} // namespace

std::unique_ptr<KmsModeset> createLegacyModeset(const KmsPipe& pipe)
{
    return std::make_unique<LegacyModeset>(pipe);
}

} // namespace replica::platform
