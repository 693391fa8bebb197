// 'replica config check FILE': the site file resolved as the kiosk resolves it (run_resolve.h),
// every problem with its file, line and key.
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <linux/magic.h>
#include <sys/statfs.h>
#include <sys/statvfs.h>

#include <platform/cli/commands.h>
#include <platform/cli/run_resolve.h>
#include <platform/logging.h>
#include <platform/site_config.h>

namespace replica::platform {
namespace {

struct ConfigOptions {
    std::string file;
    bool print = false;
};

// Why the kiosk could not keep its sessions in 'dir', or empty. The kiosk creates a missing folder
// at start and runs without recording where it cannot (a fault it survives and reports), so the
// resolve it shares with config check lets that pass; config check says it before it bites. A
// missing folder is judged by the nearest folder above it that exists, which must be a folder on a
// writable filesystem that holds folders (root may 'write' to /proc and /sys; mkdir fails there).
std::string sessionsFolderProblem(const std::filesystem::path& dir)
{
    std::error_code ec;
    std::filesystem::path at = std::filesystem::absolute(dir, ec);
    if (ec) {
        return ec.message();
    }
    while (!std::filesystem::exists(at, ec) && at.has_parent_path() && at != at.parent_path()) {
        at = at.parent_path();
    }
    if (!std::filesystem::is_directory(at, ec)) {
        return fmt::format("'{}' is not a folder", at.string());
    }
    struct statfs fs {
    };
    if (statfs(at.c_str(), &fs) == 0 &&
        (fs.f_type == PROC_SUPER_MAGIC || fs.f_type == SYSFS_MAGIC)) {
        return fmt::format("'{}' is on a kernel filesystem (/proc, /sys)", at.string());
    }
    // Not access(): the kiosk runs as its own user (the unit's StateDirectory makes its folder),
    // so whether the user checking the file may write there says nothing; a read-only mount does.
    struct statvfs vfs {
    };
    if (statvfs(at.c_str(), &vfs) == 0 && (vfs.f_flag & ST_RDONLY) != 0) {
        return fmt::format("'{}' is on a read-only filesystem", at.string());
    }
    return {};
}

int checkMain(const ConfigOptions& o)
{
    // What 'replica run --kiosk --config FILE' resolves, opening no device.
    run_cli::RunOptions run;
    run.config = o.file;
    run.kiosk = true;
    auto plan = run_cli::resolveRun(run);
    if (!plan) {
        for (const auto& line : plan.error().lines) {
            fmt::print(stderr, "{}\n", line);
        }
        return kExitFailure;
    }
    const auto& site = *plan->options.site;
    if (site.recordingEnabled) {
        if (const std::string why = sessionsFolderProblem(site.recordingDirectory); !why.empty()) {
            const SiteProblem p{
                    "recording.directory", site.lineOf("recording.directory"),
                    fmt::format("'{}' cannot hold the sessions ({}): the kiosk would run without "
                                "recording; name a folder it can write, or set "
                                "recording.enabled = false",
                                site.recordingDirectory, why)};
            fmt::print(stderr, "{}\n", formatProblem(o.file, p));
            return kExitFailure;
        }
    }
    if (o.print) {
        fmt::print("{}\n", plan->options.site->toJson());
    } else {
        fmt::print("{}: ok\n", o.file);
    }
    return kExitOk;
}

} // namespace

void registerConfigCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<ConfigOptions>();
    auto* config = app.add_subcommand("config", "the site file (/etc/replica/replica.toml)");
    config->require_subcommand(1);
    auto* check = config->add_subcommand(
            "check", "check a site file as 'replica run --kiosk' resolves it, opening no device: "
                     "every unknown key, wrong type, out-of-range or non-finite value with its "
                     "line, then the display profile, scene and booth loaded, lamp names, GPIO "
                     "lines, axes, addresses, frame size and log levels; exit 0 when the kiosk "
                     "would start, 1 otherwise");
    check->add_option("file", opts->file, "the site file")->required();
    check->add_flag("--print", opts->print, "print the resolved configuration (JSON) when good");
    check->callback([opts, &exitCode] { exitCode = checkMain(*opts); });
}

} // namespace replica::platform
