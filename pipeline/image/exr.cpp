// OpenEXR wrappers: exceptions from the library stop here and become Error values.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <stdexcept>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/output_file.h>
#include <pipeline/image/exr.h>
#include <pipeline/image/exr_chunks.h>

namespace replica::pipeline::image {

const std::vector<float>* ChannelImage::plane(const std::string& name) const
{
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (names[i] == name) {
            return &planes[i];
        }
    }
    return nullptr;
}

namespace {

// The bytes the bounded reader read, as OpenEXR's input: OpenEXR never opens the file by name
// itself (a name checked and then opened again could be a FIFO by then).
class MemoryIStream final : public Imf::IStream
{
public:
    MemoryIStream(const std::string& name, const std::string& bytes)
        : Imf::IStream(name.c_str()), bytes_(bytes)
    {}
    bool read(char c[], int n) override
    {
        if (n < 0 || pos_ > bytes_.size() || static_cast<std::size_t>(n) > bytes_.size() - pos_) {
            throw std::runtime_error("unexpected end of file");
        }
        std::memcpy(c, bytes_.data() + pos_, static_cast<std::size_t>(n));
        pos_ += static_cast<std::size_t>(n);
        return pos_ < bytes_.size();
    }
    std::uint64_t tellg() override { return pos_; }
    void seekg(std::uint64_t pos) override { pos_ = static_cast<std::size_t>(pos); }
    void clear() override {}

private:
    const std::string& bytes_;
    std::size_t pos_ = 0;
};

} // namespace

Expected<ChannelImage> readExr(const std::filesystem::path& path,
                               const std::vector<std::string>& names)
{
    // Read by the bounded reader (a regular file of bounded size: not a directory, FIFO, device
    // or symlink loop), then a bounded data window, before anything is allocated.
    auto bytes = readInputFile(path, kMaxImageBytes, "OpenEXR");
    if (!bytes) {
        if (bytes.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound, fmt::format("{}: no such file", path.string()));
        }
        return tl::unexpected(bytes.error());
    }
    ChannelImage img;
    try {
        MemoryIStream stream(path.string(), *bytes);
        Imf::InputFile file(stream);
        const Imath::Box2i dw = file.header().dataWindow();
        const std::int64_t w = std::int64_t{dw.max.x} - dw.min.x + 1;
        const std::int64_t h = std::int64_t{dw.max.y} - dw.min.y + 1;
        if (w <= 0 || h <= 0) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: empty data window", path.string()));
        }
        if (w > kMaxImageSide || h > kMaxImageSide || w * h > kMaxExrPixels) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: {}x{} pixels; at most {} per side and {} in all are "
                                         "read",
                                         path.string(), w, h, kMaxImageSide, kMaxExrPixels));
        }
        img.width = static_cast<int>(w);
        img.height = static_cast<int>(h);
        const auto n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
        Imf::FrameBuffer fb;
        img.names = names;
        img.planes.assign(names.size(), std::vector<float>(n, 0.0f));
        for (std::size_t c = 0; c < names.size(); ++c) {
            if (file.header().channels().findChannel(names[c]) == nullptr) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}: has no channel '{}'", path.string(), names[c]));
            }
            char* base = reinterpret_cast<char*>(img.planes[c].data()) -
                         (static_cast<std::ptrdiff_t>(dw.min.x) +
                          static_cast<std::ptrdiff_t>(dw.min.y) * img.width) *
                                 static_cast<std::ptrdiff_t>(sizeof(float));
            fb.insert(names[c], Imf::Slice(Imf::FLOAT, base, sizeof(float),
                                           sizeof(float) * static_cast<std::size_t>(img.width)));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: not a readable OpenEXR file ({})",
                                                         path.string(), e.what()));
    }
    if (auto chunks = checkExrChunks(*bytes, path.string()); !chunks) {
        return tl::unexpected(chunks.error());
    }
    for (std::size_t c = 0; c < names.size(); ++c) {
        const auto& p = img.planes[c];
        for (std::size_t k = 0; k < p.size(); ++k) {
            if (!std::isfinite(p[k])) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}: channel '{}' pixel ({}, {}) is {}; fix or "
                                             "re-capture the image",
                                             path.string(), names[c],
                                             k % static_cast<std::size_t>(img.width),
                                             k / static_cast<std::size_t>(img.width), p[k]));
            }
        }
    }
    return img;
}

Expected<void> writeExr(const std::filesystem::path& path,
                        const ChannelImage& img,
                        const std::vector<std::pair<std::string, std::string>>& attributes,
                        bool halfFloat)
{
    if (img.width <= 0 || img.height <= 0 || img.names.size() != img.planes.size()) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("{}: refusing to write an empty or inconsistent image", path.string()));
    }
    try {
        Imf::Header header(img.width, img.height);
        header.compression() = Imf::ZIP_COMPRESSION;
        for (const auto& [k, v] : attributes) {
            header.insert(k, Imf::StringAttribute(v));
        }
        Imf::FrameBuffer fb;
        // Half channels take half slices: OpenEXR does not convert a float buffer on output.
        std::vector<std::vector<Imath::half>> halves(halfFloat ? img.planes.size() : 0);
        for (std::size_t c = 0; c < img.names.size(); ++c) {
            header.channels().insert(img.names[c],
                                     Imf::Channel(halfFloat ? Imf::HALF : Imf::FLOAT));
            if (halfFloat) {
                halves[c].assign(img.planes[c].begin(), img.planes[c].end());
                fb.insert(img.names[c],
                          Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves[c].data()),
                                     sizeof(Imath::half),
                                     sizeof(Imath::half) * static_cast<std::size_t>(img.width)));
                continue;
            }
            fb.insert(
                    img.names[c],
                    Imf::Slice(
                            Imf::FLOAT,
                            const_cast<char*>(reinterpret_cast<const char*>(img.planes[c].data())),
                            sizeof(float), sizeof(float) * static_cast<std::size_t>(img.width)));
        }
        // Encoded in memory, then written the one safe way (pipeline/base/output_file.h).
        Imf::StdOSStream encoded;
        {
            Imf::OutputFile file(encoded, header);
            file.setFrameBuffer(fb);
            file.writePixels(img.height);
        }
        return writeOutputFile(path, encoded.str(), "OpenEXR image");
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: cannot write OpenEXR ({})", path.string(), e.what()));
    }
}

} // namespace replica::pipeline::image
