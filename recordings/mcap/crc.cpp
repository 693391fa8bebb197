// CRC-32 through zlib, fed in pieces small enough for zlib's uInt length.
#include <algorithm>

#include <zlib.h>

#include <recordings/mcap/crc.h>

namespace replica::recordings::mcap {

std::uint32_t crc32(std::uint32_t crc, std::string_view bytes)
{
    uLong c = crc;
    while (!bytes.empty()) {
        const std::size_t n = std::min<std::size_t>(bytes.size(), 1U << 30);
        c = ::crc32(c, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(n));
        bytes.remove_prefix(n);
    }
    return static_cast<std::uint32_t>(c);
}

} // namespace replica::recordings::mcap
