// CRC-32 (IEEE 802.3, zlib's crc32) as MCAP uses it for chunks, the data section and the summary.
#pragma once

#include <cstdint>
#include <string_view>

namespace replica::recordings::mcap {

// Extends a running CRC-32 over `bytes`; start from 0. crc32("123456789") == 0xCBF43926.
std::uint32_t crc32(std::uint32_t crc, std::string_view bytes);

} // namespace replica::recordings::mcap
