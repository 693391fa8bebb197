// One MCAP chunk record's fields, and its records decompressed and checked within a budget: the
// part of scanning a recording whose cost a hostile file could otherwise choose.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace replica::recordings::mcap {

struct ChunkFields {
    std::uint64_t startTime = 0, endTime = 0, uncompressedSize = 0;
    std::uint32_t crc = 0;
    std::string_view compression, records;
};

// The fields of a Chunk record's content; nullopt when they do not fill it exactly.
std::optional<ChunkFields> chunkFields(std::string_view content);

// What unpacking chunks may cost: the uncompressed bytes they may produce (and so copy and
// checksum), and what they did (Scan::bytesExamined).
struct Work {
    std::uint64_t budget = 0;
    bool overBudget = false;
    std::uint64_t examined = 0;
};

// Decompresses and checks a chunk into 'out'; returns the reason it is unusable, or "" (the
// records are in 'out'). Every chunk's uncompressed size is taken from the budget before anything
// is allocated, copied or checksummed, so that the work of every attempt (recover tries each
// plausible chunk header after damage) is bounded by the budget; 'overBudget' is set when it runs
// out (the scan then stops).
std::string unpack(const ChunkFields& c, std::string& out, Work& work);

} // namespace replica::recordings::mcap
