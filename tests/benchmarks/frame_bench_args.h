// The command line the whole-frame benchmarks share: --frames N, --size WxH, --scene NAME, --help.
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

namespace replica::bench {

struct FrameBenchArgs {
    int frames = 8;
    int width = 960;
    int height = 600;
    std::string scene; // empty: every shipped scene
};

// Parses argv into 'args' (its frames field holds the default on entry; at least 'minFrames').
// Returns the exit code when the program should stop now (0 after --help, 2 on a bad argument,
// with one line on stderr), nothing when it should run.
inline std::optional<int>
parseFrameBenchArgs(int argc, char** argv, FrameBenchArgs& args, int minFrames, const char* what)
{
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        if (arg == "--help" || arg == "-h") {
            std::printf("usage: %s [--frames N] [--size WxH] [--scene NAME]\n%s\n", argv[0], what);
            return 0;
        }
        if (a + 1 < argc && arg == "--frames") {
            args.frames = std::max(minFrames, std::atoi(argv[++a]));
        } else if (a + 1 < argc && arg == "--size") {
            if (std::sscanf(argv[++a], "%dx%d", &args.width, &args.height) != 2 || args.width < 1 ||
                args.height < 1) {
                std::fprintf(stderr, "--size: expected WIDTHxHEIGHT, got %s\n", argv[a]);
                return 2;
            }
        } else if (a + 1 < argc && arg == "--scene") {
            args.scene = argv[++a];
        } else {
            std::fprintf(stderr, "unknown argument %s (see --help)\n", arg.c_str());
            return 2;
        }
    }
    return std::nullopt;
}

} // namespace replica::bench
