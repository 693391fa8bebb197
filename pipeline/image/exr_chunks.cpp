// Every scan-line chunk of an OpenEXR file decoded by OpenEXR's core library, which checks what
// the C++ reader does not: that each chunk decompresses to exactly the bytes its header says.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include <OpenEXR/openexr.h>
#include <fmt/format.h>

#include <pipeline/image/exr_chunks.h>

namespace replica::pipeline::image {
namespace {

struct Source {
    const std::string* bytes;
};

int64_t readAt(exr_const_context_t /*ctxt*/,
               void* userdata,
               void* buffer,
               uint64_t size,
               uint64_t offset,
               exr_stream_error_func_ptr_t /*errorCb*/)
{
    const std::string& bytes = *static_cast<Source*>(userdata)->bytes;
    if (offset >= bytes.size()) {
        return 0; // past the end: the library reports a short read
    }
    const auto n = std::min<uint64_t>(size, bytes.size() - offset);
    std::memcpy(buffer, bytes.data() + offset, n);
    return static_cast<int64_t>(n);
}

int64_t sizeOf(exr_const_context_t /*ctxt*/, void* userdata)
{
    return static_cast<int64_t>(static_cast<Source*>(userdata)->bytes->size());
}

// The library would print its own messages on stderr; ours name the file instead.
void quiet(exr_const_context_t /*ctxt*/, exr_result_t /*code*/, const char* /*msg*/)
{}

// Decodes one chunk's every channel as float into 'scratch' (its size grown as needed).
exr_result_t decodeChunk(exr_context_t ctx,
                         int y,
                         exr_decode_pipeline_t& decode,
                         bool& initialised,
                         std::vector<float>& scratch)
{
    exr_chunk_info_t chunk{};
    exr_result_t rv = exr_read_scanline_chunk_info(ctx, 0, y, &chunk);
    if (rv != EXR_ERR_SUCCESS) {
        return rv;
    }
    rv = initialised ? exr_decoding_update(ctx, 0, &chunk, &decode)
                     : exr_decoding_initialize(ctx, 0, &chunk, &decode);
    if (rv != EXR_ERR_SUCCESS) {
        return rv;
    }
    initialised = true;
    std::size_t total = 0;
    for (int c = 0; c < decode.channel_count; ++c) {
        const auto& ch = decode.channels[c];
        total += static_cast<std::size_t>(std::max(ch.width, 0)) *
                 static_cast<std::size_t>(std::max(ch.height, 0));
    }
    scratch.resize(std::max<std::size_t>(total, 1));
    std::size_t at = 0;
    for (int c = 0; c < decode.channel_count; ++c) {
        auto& ch = decode.channels[c];
        ch.decode_to_ptr = reinterpret_cast<uint8_t*>(scratch.data() + at);
        ch.user_pixel_stride = sizeof(float);
        ch.user_line_stride = static_cast<int32_t>(sizeof(float)) * std::max(ch.width, 0);
        ch.user_bytes_per_element = sizeof(float);
        ch.user_data_type = EXR_PIXEL_FLOAT;
        at += static_cast<std::size_t>(std::max(ch.width, 0)) *
              static_cast<std::size_t>(std::max(ch.height, 0));
    }
    rv = exr_decoding_choose_default_routines(ctx, 0, &decode);
    if (rv != EXR_ERR_SUCCESS) {
        return rv;
    }
    return exr_decoding_run(ctx, 0, &decode);
}

exr_result_t decodeEveryChunk(exr_context_t ctx)
{
    exr_storage_t storage{};
    exr_result_t rv = exr_get_storage(ctx, 0, &storage);
    if (rv != EXR_ERR_SUCCESS || storage != EXR_STORAGE_SCANLINE) {
        return rv; // tiled and deep files are left to the C++ reader, which refuses them
    }
    exr_attr_box2i_t dw{};
    int32_t lines = 0;
    if ((rv = exr_get_data_window(ctx, 0, &dw)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_scanlines_per_chunk(ctx, 0, &lines)) != EXR_ERR_SUCCESS) {
        return rv;
    }
    exr_decode_pipeline_t decode = EXR_DECODE_PIPELINE_INITIALIZER;
    bool initialised = false;
    std::vector<float> scratch;
    for (int64_t y = dw.min.y; y <= dw.max.y && rv == EXR_ERR_SUCCESS; y += std::max(lines, 1)) {
        rv = decodeChunk(ctx, static_cast<int>(y), decode, initialised, scratch);
    }
    if (initialised) {
        exr_decoding_destroy(ctx, &decode);
    }
    return rv;
}

} // namespace

Expected<void> checkExrChunks(const std::string& bytes, const std::string& name)
{
    Source source{&bytes};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &source;
    init.read_fn = &readAt;
    init.size_fn = &sizeOf;
    init.error_handler_fn = &quiet;
    exr_context_t ctx = nullptr;
    exr_result_t rv = exr_start_read(&ctx, name.c_str(), &init);
    if (rv == EXR_ERR_SUCCESS) {
        rv = decodeEveryChunk(ctx);
    }
    if (ctx != nullptr) {
        exr_finish(&ctx);
    }
    if (rv != EXR_ERR_SUCCESS) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: not a readable OpenEXR file (a chunk does not decode to "
                                     "what its header says: {}); re-export or re-capture it",
                                     name, exr_get_default_error_message(rv)));
    }
    return {};
}

} // namespace replica::pipeline::image
