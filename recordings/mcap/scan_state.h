// What a scan of a recording holds while it reads, shared by the data section's scan (reader.cpp)
// and the summary's checks (summary_check.cpp). Internal to the reader.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include <recordings/mcap/reader.h>

namespace replica::recordings::mcap::detail {

struct ScanState {
    ScanState(Source& in, const ScanOptions& o) : in_(in), size_(in.size()), o_(o) {}

    void problem(std::string what)
    {
        ++s_.damageCount;
        if (s_.damage.size() < o_.maxDamageReports) {
            s_.damage.push_back(std::move(what));
        }
    }

    // The content of the record at `at`, for one the scan parses whole: nullopt when it is longer
    // than any such record may be (damage, reported) or cannot be read. Read together with its
    // prefix, so that the window never moves past `at` (resynchronisation goes on from at + 1).
    std::optional<std::string_view> content(std::size_t at, std::uint64_t len, const char* kind)
    {
        if (len > kMaxRecordBytes) {
            problem(fmt::format(
                    "{} record at byte {} claims {} bytes, more than the {} MiB one may "
                    "hold",
                    kind, at, len, kMaxRecordBytes >> 20));
            return std::nullopt;
        }
        const auto whole = read(at, kRecordPrefix + len);
        return whole ? std::optional(whole->substr(kRecordPrefix)) : std::nullopt;
    }

    // Bytes of the file; one that cannot be read ends the scan, the source's reason in the Scan.
    std::optional<std::string_view> read(std::uint64_t at, std::uint64_t n)
    {
        auto bytes = in_.bytes(at, n);
        if (!bytes && s_.readError.empty()) {
            s_.readError = in_.error();
        }
        return bytes;
    }

    // The CRC-32 of bytes [from, to); 0 when they cannot be read (readError says so).
    std::uint32_t crcOf(std::uint64_t from, std::uint64_t to)
    {
        const auto c = in_.crc(from, to);
        if (!c && s_.readError.empty()) {
            s_.readError = in_.error();
        }
        return c.value_or(0);
    }

    Source& in_;
    std::uint64_t size_ = 0;
    ScanOptions o_;
    Scan s_;
};

// Checks the footer, trailing magic, summary CRC, and the summary's indexes and statistics against
// the data section the scan found (the scan is at its Data End record; the summary starts at
// afterDataEnd).
void checkSummary(ScanState& st, std::size_t afterDataEnd);

} // namespace replica::recordings::mcap::detail
