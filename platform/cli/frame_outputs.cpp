// Digest and snapshot collection.
#include <platform/cli/frame_outputs.h>
#include <platform/image/png_metadata.h>
#include <platform/image/png_writer.h>

namespace replica::platform {

pipeline::render::Readback FrameOutputs::readback() const
{
    using pipeline::render::Readback;
    return digest_ ? Readback::DisplayAndXyz : (keepLast_ ? Readback::Display : Readback::None);
}

void FrameOutputs::add(const recordings::FrameRecord& f,
                       const pipeline::render::RenderedFrame& image)
{
    if (digest_) {
        const auto* xyzBytes = reinterpret_cast<const std::uint8_t*>(image.xyz.data());
        digests_.push_back({f.frameIndex, f.tickNs,
                            frameHash(hash_, {xyzBytes, image.xyz.size() * sizeof(float)}),
                            frameHash(hash_, image.rgba)});
    }
    if (keepLast_) {
        lastWidth_ = image.width;
        lastHeight_ = image.height;
        lastRgba_ = image.rgba;
        lastTickNs_ = f.tickNs;
        lastFrame_ = f.frameIndex;
    }
}

Expected<void> FrameOutputs::finish(const std::string& digestPath,
                                    const std::string& snapshotPath) const
{
    if (!digestPath.empty()) {
        if (auto ok = writeDigests(digestPath, digests_, hash_); !ok) {
            return ok;
        }
    }
    if (!snapshotPath.empty()) {
        if (lastRgba_.empty()) {
            return makeError(ErrorCode::InvalidArgument,
                             snapshotPath +
                                     ": no frame was rendered, so there is nothing to snapshot");
        }
        if (tagged_) {
            const PngMetadata meta =
                    shownFrameMetadata(icc_, iccName_, wallStartNs_, lastTickNs_, lastFrame_);
            return writePng(snapshotPath, lastWidth_, lastHeight_, lastRgba_, &meta);
        }
        return writePng(snapshotPath, lastWidth_, lastHeight_, lastRgba_);
    }
    return {};
}

} // namespace replica::platform
