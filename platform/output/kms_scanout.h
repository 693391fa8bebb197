// The KMS scan-out the two KMS outputs (kms_output.cpp) sit on: KmsScanout picks the connector, its
// mode and a CRTC, and a modesetting strategy (kms_modeset.h: atomic where the driver offers it,
// else legacy); it sets the mode with the first frame and page-flips each later one on vertical
// blank, waiting for the flip's event so that the buffer drawn next is no longer on screen.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <xf86drmMode.h>

#include <pipeline/base/expected.h>
#include <platform/output/kms_modeset.h>
#include <platform/output/output.h>

namespace replica::platform {

class KmsScanout
{
public:
    // Takes the open card fd (closed with the scan-out).
    KmsScanout(int fd, std::string device);
    ~KmsScanout();
    KmsScanout(const KmsScanout&) = delete;
    KmsScanout& operator=(const KmsScanout&) = delete;

    Expected<void> init(const KmsOptions& o);

    // Shows framebuffer fb: the first call sets the mode, later ones flip on vertical blank and
    // return once the flip has happened.
    Expected<void> show(std::uint32_t fb);

    // Puts back what the CRTC showed before (the console) once a frame has been shown.
    void restore();

    int fd() const { return pipe_.fd; }
    const std::string& device() const { return pipe_.device; }
    int width() const { return pipe_.mode.hdisplay; }
    int height() const { return pipe_.mode.vdisplay; }
    DisplayInfo info() const;
    std::string describe() const;

private:
    Expected<drmModeConnector*> pickConnector(const drmModeRes& res, const KmsOptions& o);
    Expected<void>
    pickMode(const drmModeConnector& connector, const ModeRequest& request, const KmsOptions& o);
    void pickCrtc(const drmModeRes& res, const drmModeConnector& connector);
    Expected<void> pickModeset(const KmsOptions& o);
    Expected<void> setMode(std::uint32_t fb);

    KmsPipe pipe_;
    std::optional<SizeMm> edid_;
    std::unique_ptr<KmsModeset> modeset_;
    drmModeCrtc* saved_ = nullptr;
    bool modeSet_ = false;
    bool flipped_ = false;
};

// The two ways to get frames into scan-out buffers (kms_gbm_output.cpp, kms_dumb_output.cpp).
// EGL on a GBM surface of the card: the renderer draws into its own framebuffers in that context,
// present() copies the finished frame on the GPU into the surface, swaps and flips. Makes its
// context current.
Expected<std::unique_ptr<Output>> createGbmKmsOutput(std::shared_ptr<KmsScanout> scanout);
// The fallback where the card has no GBM/EGL driver: a surfaceless context whose frames are read
// back and copied into double-buffered dumb buffers.
Expected<std::unique_ptr<Output>> createDumbKmsOutput(std::shared_ptr<KmsScanout> scanout);

} // namespace replica::platform
