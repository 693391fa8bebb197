// 'replica display patches': show a patch set in order and collect one reading per patch, from
// ArgyllCMS spotread driven as a subprocess or typed on stdin, into a .ti3 that is rewritten after
// every reading (an interrupted run resumes from it).
#pragma once

#include <cstdint>
#include <string>

namespace replica::platform {

struct PatchesOptions {
    std::string set;     // .ti1 to show
    std::string out;     // .ti3 readings (resumed when it exists)
    std::string showDir; // headless display: patch.png and patch.txt of the patch on show
    std::string output = "headless"; // "headless" (--show-dir) or "kms": fullscreen on the panel
    std::string kmsDevice = "/dev/dri/card0";
    std::string kmsConnector; // empty: the first connected one
    std::string spotread;     // command line of the meter; empty: readings on stdin
    std::string makeSet;      // write the default patch set here and stop
    int bits = 8;
    int settleMs = 0;
    int step = 3;
    int fullDriveRepeats = 10; // each primary's full drive, read this many times
    int colours = 60;
    std::uint64_t seed = 1;
};

int patchesMain(const PatchesOptions& o);

} // namespace replica::platform
