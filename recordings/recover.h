// Rebuilding a valid recording from a truncated or partly corrupted one ('replica recover').
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::recordings {

struct RecoverReport {
    std::uint64_t messagesKept = 0;
    std::uint64_t chunksKept = 0;      // intact chunks whose messages were all kept
    std::uint64_t chunksDamaged = 0;   // chunk records dropped because they failed a check
    std::uint64_t bytesDropped = 0;    // input bytes that were not part of any intact record
    std::uint64_t messagesDropped = 0; // messages seen but unusable, plus any the summary claimed
    std::vector<std::string> problems; // what was wrong, one sentence each
    std::vector<std::uint16_t> channelsAssumed; // channel definitions re-created from the format
    bool sessionRestored = false; // the session message came from the replica.session metadata
    // Something was dropped. A restored session means the first chunk, which held it (and the
    // first samples), is gone, even when it was cut out so cleanly that nothing else shows it.
    bool lossy() const
    {
        return bytesDropped > 0 || messagesDropped > 0 || chunksDamaged > 0 || sessionRestored;
    }
};

// What recover does when its output already exists ('replica recover --force': Replace).
enum class ExistingOutput { Refuse, Replace };

// Reads `in` linearly (no footer needed), resynchronising on the next intact chunk after damage,
// and writes every message it could keep to `out` as a complete, indexed recording. Fails when
// `in` cannot be read, nothing is recoverable, or `out` cannot be written (ErrorCode::Io: a read or
// write failed, or `in` changed between the two passes). `in` is read twice through a bounded
// window (mcap::FileSource), once for its channels, metadata and damage, once to copy its messages
// into the writer as they come: memory does not grow with the file (docs/limits.md).
// The output is written to a new file beside `out` and renamed onto it only once complete and
// synced, so an interrupted or failed recover leaves `out` as it was (and `in` is only read).
// `out` must not be `in`, a symbolic link (never followed nor replaced), a directory or any other
// non-regular file; an existing regular file is refused unless `existing` is Replace.
Expected<RecoverReport> recoverRecording(const std::filesystem::path& in,
                                         const std::filesystem::path& out,
                                         ExistingOutput existing);

} // namespace replica::recordings
