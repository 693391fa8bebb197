// KMS modesetting as two strategies behind one interface (as kmscube's drm-atomic.c and
// drm-legacy.c): atomic commits of the connector, CRTC and primary plane (kms_atomic.cpp), or the
// legacy drmModeSetCrtc / drmModePageFlip calls (kms_legacy.cpp). KmsScanout (kms_scanout.h)
// chooses one and waits for the flips' events.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <xf86drmMode.h>

#include <pipeline/base/expected.h>

namespace replica::platform {

// What KmsScanout chose to drive: the card, the connector, its mode and a CRTC.
struct KmsPipe {
    int fd = -1;
    std::string device; // e.g. /dev/dri/card0
    std::string label;  // the connector, e.g. HDMI-A-1
    drmModeModeInfo mode{};
    std::uint32_t connectorId = 0;
    std::uint32_t crtcId = 0;
    int crtcIndex = 0;
};

class KmsModeset
{
public:
    virtual ~KmsModeset() = default;
    virtual bool atomic() const = 0;
    // Sets the mode showing framebuffer fb (the first frame).
    virtual Expected<void> setMode(std::uint32_t fb) = 0;
    // Asks for a flip to fb on vertical blank; its event carries eventData.
    virtual Expected<void> flip(std::uint32_t fb, void* eventData) = 0;
};

// Atomic modesetting on the pipe's CRTC and its primary plane; null, with 'why' saying what is
// missing, where the driver does not offer it. Sets the card's atomic client capabilities.
std::unique_ptr<KmsModeset> createAtomicModeset(const KmsPipe& pipe, std::string& why);
std::unique_ptr<KmsModeset> createLegacyModeset(const KmsPipe& pipe);

// The id of the property 'name' of a KMS object, 0 when it has none.
std::uint32_t propertyId(int fd, std::uint32_t object, std::uint32_t type, const char* name);
// The value of the property 'name', when the object has it.
std::optional<std::uint64_t>
propertyValue(int fd, std::uint32_t object, std::uint32_t type, const char* name);

} // namespace replica::platform
