// The output interface: where rendered frames go (headless, or KMS scan-out).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::platform {

// An 8-bit RGBA frame as it would be scanned out, rows bottom-up as GL reads them.
struct DisplayFrame {
    int width = 0;
    int height = 0;
    std::span<const std::uint8_t> rgba;
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
};

// A surfaceless EGL context with GLES 3 (Mesa llvmpipe where there is no GPU); frames are kept in
// memory only. Makes its context current on the calling thread.
Expected<std::unique_ptr<Output>> createHeadlessOutput();

// Fullscreen on a display with no display server: renders with the same surfaceless context and
// scans frames out through KMS on 'device' (e.g. /dev/dri/card0), on the first connected
// connector or the named one ("HDMI-A-1"), in its preferred mode. Frames smaller than the mode are
// centred on black.
Expected<std::unique_ptr<Output>> createKmsOutput(const std::string& device,
                                                  const std::string& connector = {});

} // namespace replica::platform
