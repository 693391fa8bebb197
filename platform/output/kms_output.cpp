// KMS output: the appliance's fullscreen path on a console with no display server.
//
// KmsScanout (kms_scanout.h) picks the connector, its mode, a CRTC and the modesetting strategy
// (kms_modeset.h: atomic, kms_atomic.cpp, or legacy, kms_legacy.cpp), sets the mode with the
// first frame and page-flips each later one on vertical blank. Two ways to get frames into
// scan-out buffers sit on it:
//  - the GBM output (kms_gbm_output.cpp, the normal path): EGL on a GBM surface of the card, the
//    finished frame copied on the GPU into the surface. No read-back.
//  - the dumb-buffer output (kms_dumb_output.cpp, the fallback where the card has no GBM/EGL
//    driver): a surfaceless context whose frames are read back and copied into double-buffered
//    dumb buffers (scanout_copy.h).
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <memory>

#include <fcntl.h>
#include <fmt/format.h>

#include <platform/logging.h>
#include <platform/output/kms_scanout.h>
#include <platform/output/output.h>

namespace replica::platform {
namespace {

std::string envOr(const char* name, const std::string& fallback)
{
    const char* v = std::getenv(name);
    return v != nullptr && *v != '\0' ? std::string(v) : fallback;
}

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
    KmsOptions resolved = options;
    resolved.modeset = envOr("REPLICA_KMS_MODESET", options.modeset);
    if (auto ok = scanout->init(resolved); !ok) {
        return tl::unexpected(ok.error());
    }
    const std::string path = envOr("REPLICA_KMS_PATH", options.path);
    if (path != "auto" && path != "gbm" && path != "dumb") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("KMS path '{}': expected auto, gbm or dumb", path));
    }
    auto log = logger("output");
    if (path != "dumb") {
        auto gbm = createGbmKmsOutput(scanout);
        if (gbm) {
            log->info("kms: {}: EGL on a GBM surface, frames copied on the GPU and page-flipped",
                      scanout->describe());
            return std::move(*gbm);
        }
        if (path == "gbm") {
            return tl::unexpected(gbm.error());
        }
        log->warn("kms: {}; falling back to CPU copies into dumb buffers", gbm.error().message);
    }
    auto out = createDumbKmsOutput(scanout);
    if (!out) {
        return out;
    }
    log->info("kms: {}: frames read back and copied into dumb buffers", scanout->describe());
    return out;
}

} // namespace replica::platform
