// 'replica figures OUT_DIR': the paper's Figs. 2-7 regenerated from the shipped data. The panels
// are rendered by this binary's 'render' command; the shipped script data/figures/figures.py drives
// the renders, measures the numbers behind each figure (CSV) and lays out the PNGs with matplotlib
// (python3-matplotlib, which deploy/install-deps installs).
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>

#include <pipeline/base/data_dir.h>
#include <platform/cli/commands.h>

extern char** environ;

namespace replica::platform {
namespace {

struct FiguresArgs {
    std::string outDir;
    bool quick = false;
    double scale = 2.0;
    std::string only = "2,3,4,5,6,7";
    bool gl = false;
    std::string python = "/usr/bin/python3";
};

int fail(int code, const std::string& message)
{
    std::fprintf(stderr, "replica figures: %s\n", message.c_str());
    return code;
}

int runFigures(const FiguresArgs& a)
{
    const std::filesystem::path script = dataDir() / "figures" / "figures.py";
    if (!std::filesystem::is_regular_file(script)) {
        return fail(kExitFailure, fmt::format("{} is missing (the shipped data folder is "
                                              "incomplete; REPLICA_DATA_DIR names another)",
                                              script.string()));
    }
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) {
        return fail(kExitFailure, "cannot find this program's own path: " + ec.message());
    }
    std::filesystem::create_directories(a.outDir, ec);
    if (ec) {
        return fail(kExitFailure, fmt::format("cannot make {}: {}", a.outDir, ec.message()));
    }
    std::vector<std::string> args = {
            a.python,           script.string(), a.outDir,
            "--replica",        self.string(),   "--data",
            dataDir().string(), "--scale",       fmt::format("{}", a.quick ? 0.5 : a.scale),
            "--only",           a.only};
    if (a.gl) {
        args.emplace_back("--gl");
    }
    std::vector<char*> argv;
    for (auto& s : args) {
        argv.push_back(s.data());
    }
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (const int err = posix_spawn(&pid, a.python.c_str(), nullptr, nullptr, argv.data(), environ);
        err != 0) {
        return fail(kExitFailure, fmt::format("cannot run {}: {} (python3 with matplotlib: "
                                              "deploy/install-deps installs it)",
                                              a.python, std::strerror(err)));
    }
    int status = 0;
    if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        return fail(kExitFailure, fmt::format("{} failed (its message is above)", script.string()));
    }
    std::printf("%s: fig2..fig7 (.png, .txt caption with each panel's command, .csv numbers)\n",
                a.outDir.c_str());
    return kExitOk;
}

} // namespace

void registerFiguresCommand(CLI::App& app, int& exitCode)
{
    auto args = std::make_shared<FiguresArgs>();
    CLI::App* cmd = app.add_subcommand(
            "figures",
            "regenerate the paper's Figs. 2-7 from the shipped data (PNG, captions, CSV)");
    cmd->footer("Writes OUT_DIR/figN.png, figN.txt (what it shows and the exact command line of "
                "each panel) and figN.csv (the numbers behind it) for N = 2..7: the booth lamps' "
                "luminance (2), the painting shading-only (3), its shadowing as the panel tilts "
                "(4), a curved glossy surface under tungsten and D65 (5), the ColorChecker under "
                "D65, D50 and A at a 5500 K white balance (6), the metamer pairs (7); the rendered "
                "panels (absolute XYZ OpenEXR) go to OUT_DIR/panels. Progress on stderr. Needs "
                "python3 with matplotlib (deploy/install-deps). docs/figures.md shows them.");
    cmd->add_option("OUT_DIR", args->outDir, "folder for the figures (made if missing)")
            ->required();
    cmd->add_flag("--quick", args->quick,
                  "panels at half the scenes' texel size (--scale 0.5): the test's size");
    cmd->add_option("--scale", args->scale, "panel pixels per scene texel")
            ->check(CLI::Range(0.1, 8.0))
            ->capture_default_str();
    cmd->add_option("--only", args->only, "comma-separated figure numbers to make")
            ->check(CLI::Validator(
                    [](std::string& s) {
                        for (const char c : s) {
                            if (c != ',' && (c < '2' || c > '7')) {
                                return std::string("figure numbers 2-7, comma-separated");
                            }
                        }
                        return std::string();
                    },
                    "LIST", "LIST"))
            ->capture_default_str();
    cmd->add_flag("--gl", args->gl,
                  "render the panels with the GLES pass through surfaceless EGL (what the "
                  "appliance runs) instead of its CPU model");
    cmd->add_option("--python", args->python, "the Python 3 with matplotlib that lays them out")
            ->capture_default_str();
    cmd->callback([args, &exitCode] { exitCode = runFigures(*args); });
}

} // namespace replica::platform
