// What 'replica run' and 'replica replay' report of the frames a loop ran: the keys their --json
// summaries share and the log lines that say the same in words.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include <platform/loop/frame_digest.h>
#include <platform/loop/frame_loop.h>

namespace replica::platform {

// "frames", "late_frames", "dropped" (per device), "frame_time_ms" (mean, p50, p95, p99, max and
// how many frames took the whole period or more) and "out_of_gamut" (fractions of the surface's
// pixels) for a loop at 'periodMs'.
nlohmann::json loopSummaryJson(const LoopStats& stats, double periodMs);

// "digests": the digest file and its hash.
nlohmann::json digestsJson(const std::string& file, DigestHash hash);

// The loop's frames, drops, late frames, gamut and frame times at info level. 'digests': the run
// read every frame back for --digests (said, as it costs frame time a run without it does not pay).
void logLoopSummary(const LoopStats& stats, double periodMs, bool digests);

} // namespace replica::platform
