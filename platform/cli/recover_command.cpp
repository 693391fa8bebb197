// 'replica recover IN OUT': rebuild a valid recording from a truncated or damaged one.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <platform/cli/commands.h>
#include <platform/logging.h>
#include <recordings/recover.h>

namespace replica::platform {
namespace {

struct RecoverOptions {
    std::string in, out;
    bool json = false;
    bool force = false;
};

int recoverMain(const RecoverOptions& o)
{
    auto r = recordings::recoverRecording(o.in, o.out,
                                          o.force ? recordings::ExistingOutput::Replace
                                                  : recordings::ExistingOutput::Refuse);
    if (!r) {
        if (o.json) {
            fmt::print("{}\n", nlohmann::json{{"error", r.error().message}}.dump(2));
        }
        logger("replica")->error("{}", r.error().message);
        return kExitFailure;
    }
    const int code = r->lossy() ? kExitLossy : kExitOk;
    if (o.json) {
        fmt::print("{}\n", nlohmann::json{{"input", o.in},
                                          {"output", o.out},
                                          {"messages_kept", r->messagesKept},
                                          {"chunks_kept", r->chunksKept},
                                          {"chunks_dropped", r->chunksDamaged},
                                          {"bytes_dropped", r->bytesDropped},
                                          {"messages_dropped", r->messagesDropped},
                                          {"channels_assumed", r->channelsAssumed},
                                          {"session_restored", r->sessionRestored},
                                          {"problems", r->problems},
                                          {"lossy", r->lossy()}}
                                   .dump(2));
        return code;
    }
    for (const auto& p : r->problems) {
        fmt::print("found: {}\n", p);
    }
    if (r->sessionRestored) {
        fmt::print("found: the session message was missing (its chunk lost): restored from the "
                   "copy in the metadata\n");
    }
    fmt::print("{}: kept {} messages from {} intact chunks; dropped {} damaged chunks, {} bytes, "
               "{} messages{}\n",
               o.out, r->messagesKept, r->chunksKept, r->chunksDamaged, r->bytesDropped,
               r->messagesDropped, r->lossy() ? "" : " (nothing lost)");
    return code;
}

} // namespace

void registerRecoverCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<RecoverOptions>();
    auto* cmd = app.add_subcommand(
            "recover", "rebuild a valid recording from a truncated or damaged one, keeping every "
                       "intact chunk; exit 0 nothing lost, 3 something dropped, 1 nothing "
                       "recoverable");
    cmd->add_option("in", opts->in, "damaged recording (.mcap)")->required();
    cmd->add_option("out", opts->out, "where to write the rebuilt recording")->required();
    cmd->add_flag("--json", opts->json, "print the report as JSON");
    cmd->add_flag("--force", opts->force,
                  "replace OUT if it is an existing regular file (written beside it, then "
                  "renamed onto it; a symbolic link is never followed or replaced)");
    cmd->callback([opts, &exitCode] { exitCode = recoverMain(*opts); });
}

} // namespace replica::platform
