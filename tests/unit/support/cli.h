// Running the built 'replica' binary from a test.
#pragma once

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace replica::tests {

struct CliResult {
    int exitCode = -1;
    std::string out; // stdout
    std::string err; // stderr
};

// Runs the built binary with 'args' (shell words): stdout captured, stderr through a file in 'dir'
// (the calling test's own directory: ctest runs tests side by side).
inline CliResult runReplica(const std::string& args, const std::filesystem::path& dir)
{
    const auto errPath = dir / "stderr.txt";
    const std::string cmd = std::string(REPLICA_BINARY) + " " + args + " 2>" + errPath.string();
    CliResult r;
    FILE* pipe = popen(cmd.c_str(), "r");
    if (pipe == nullptr) {
        return r;
    }
    char buf[4096];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) {
        r.out.append(buf, n);
    }
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream e(errPath);
    r.err.assign(std::istreambuf_iterator<char>(e), std::istreambuf_iterator<char>());
    return r;
}

} // namespace replica::tests
