// The output interface: where rendered frames go (headless, or KMS scan-out).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <platform/output/display_geometry.h>

namespace replica::platform {

// An 8-bit RGBA frame as it would be scanned out, rows bottom-up as GL reads them: in memory
// (rgba, when the renderer read it back) and, in the output's GL context, as the framebuffer that
// holds it (glFramebuffer, 0 when there is none), which an output on the GPU copies without a
// read-back.
struct DisplayFrame {
    int width = 0;
    int height = 0;
    std::span<const std::uint8_t> rgba;
    unsigned glFramebuffer = 0;
};

// The display an output drives: the mode (the frame size a run takes) and what the display says
// of its physical size (EDID), when it says.
struct DisplayInfo {
    int width = 0;
    int height = 0;
    std::optional<SizeMm> edidSize;
    std::string connector;
};

// Owns the GL context the renderer draws with, and takes each finished frame.
class Output
{
public:
    virtual ~Output() = default;
    virtual std::string name() const = 0;
    // GL_RENDERER of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    virtual std::string glRenderer() const = 0;
    virtual Expected<void> present(const DisplayFrame& frame) = 0;
    // Whether present() reads frame.rgba (a CPU copy to scan out); otherwise the renderer need not
    // read frames back for it.
    virtual bool needsPixels() const { return false; }
    // The display driven, or nullopt when there is none (headless).
    virtual std::optional<DisplayInfo> display() const { return std::nullopt; }
};

// A surfaceless EGL context with GLES 3 (Mesa llvmpipe where there is no GPU); frames are kept in
// memory only. Makes its context current on the calling thread.
Expected<std::unique_ptr<Output>> createHeadlessOutput();

struct KmsOptions {
    std::string device = "/dev/dri/card0";
    std::string connector;        // e.g. "HDMI-A-1"; empty: the first connected one
    std::string mode;             // "WIDTHxHEIGHT[@HZ]"; empty: the connector's preferred mode
    bool modeOrPreferred = false; // a mode the display lacks: its preferred one, not an error
    // "auto": atomic modesetting where the driver offers it, else the legacy calls; "atomic" or
    // "legacy" to force one (REPLICA_KMS_MODESET overrides).
    std::string modeset = "auto";
    // "auto": EGL on a GBM surface of the card, else CPU copies into dumb buffers; "gbm" or "dumb"
    // to force one (REPLICA_KMS_PATH overrides).
    std::string path = "auto";
};

// Fullscreen on a display with no display server, through KMS on options.device: renders with EGL
// on a GBM surface of the card (the frame is copied on the GPU into the surface, swapped and page
// flipped on vertical blank), or where that fails (no GBM/EGL for the card) with a surfaceless
// context whose frames are read back and copied into dumb buffers. Logs which. Frames smaller than
// the mode are centred on black, larger ones cropped.
Expected<std::unique_ptr<Output>> createKmsOutput(const KmsOptions& options);

} // namespace replica::platform
