// Area loggers and level parsing.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <sys/stat.h>
#include <sys/uio.h>

#include <pipeline/base/printable.h>
#include <platform/logging.h>

#ifdef REPLICA_HAVE_LIBSYSTEMD
#include <systemd/sd-journal.h>
#endif

namespace replica::platform {
namespace {

const char* const kAreas[] = {
        "hal.spectrometer", "hal.tracker", "hal.accel", "hal.lamp", "pipeline",
        "render",           "output",      "rec",       "loop",     "replica",
        "planner",          "booth",       "state"};

// The message of a log line with its control characters escaped (pipeline/base/printable.h):
// a log line may carry text from a recording or a device, and a terminal must not obey it.
class PrintableMessage final : public spdlog::custom_flag_formatter
{
public:
    void format(const spdlog::details::log_msg& msg,
                const std::tm& /*time*/,
                spdlog::memory_buf_t& dest) override
    {
        const auto text = printable(std::string_view(msg.payload.data(), msg.payload.size()),
                                    std::string_view::npos, true);
        dest.append(text.data(), text.data() + text.size());
    }
    std::unique_ptr<custom_flag_formatter> clone() const override
    {
        return std::make_unique<PrintableMessage>();
    }
};

std::mutex& registryMutex()
{
    static std::mutex m;
    return m;
}

// spdlog's own parser, which answers 'off' for any name it does not know: a typo must not switch
// every logger off.
std::optional<spdlog::level::level_enum> parseLevel(const std::string& name)
{
    const auto level = spdlog::level::from_str(name);
    if (level == spdlog::level::off && name != "off") {
        return std::nullopt;
    }
    return level;
}

// One item of a --log-level spec ("level" for every area, or "name=level"; items are comma
// separated, empty ones skipped).
struct SpecItem {
    std::string text;
    std::optional<std::string> name; // none: every area
    std::string level;
};

std::vector<SpecItem> specItems(const std::string& spec)
{
    std::vector<SpecItem> items;
    std::istringstream in(spec);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item.empty()) {
            continue;
        }
        const auto eq = item.find('=');
        if (eq == std::string::npos) {
            items.push_back({item, std::nullopt, item});
        } else {
            items.push_back({item, item.substr(0, eq), item.substr(eq + 1)});
        }
    }
    return items;
}

class TapSink final : public spdlog::sinks::base_sink<std::mutex>
{
public:
    explicit TapSink(LogTap tap) : tap_(std::move(tap)) {}

protected:
    void sink_it_(const spdlog::details::log_msg& msg) override
    {
        tap_(msg.level, std::string(msg.logger_name.begin(), msg.logger_name.end()),
             std::string(msg.payload.begin(), msg.payload.end()));
    }
    void flush_() override {}

private:
    LogTap tap_;
};

// An area's lines to the journal: the native protocol (sd_journal_sendv: MESSAGE "[area] text",
// PRIORITY, SYSLOG_IDENTIFIER=replica, REPLICA_LOGGER=area) where journald's socket is there, or
// else (or in a build without libsystemd, or should a send fail) "<PRIORITY>[area] text" on
// stderr, which journald files under that priority. sd_journal_sendv reports success when the
// socket is missing, hence the look at the socket first. One sink per logger: tapLogs sets a
// logger's sinks' levels one by one.
class JournalSink final : public spdlog::sinks::base_sink<std::mutex>
{
protected:
    void sink_it_(const spdlog::details::log_msg& msg) override
    {
        const std::string area(msg.logger_name.begin(), msg.logger_name.end());
        // Control characters escaped, as on the console (pipeline/base/printable.h).
        const auto text = printable(std::string_view(msg.payload.data(), msg.payload.size()),
                                    std::string_view::npos, false);
#ifdef REPLICA_HAVE_LIBSYSTEMD
        static const bool native = [] {
            struct stat st {
            };
            return stat("/run/systemd/journal/socket", &st) == 0 && S_ISSOCK(st.st_mode);
        }();
        std::string fields[] = {"MESSAGE=[" + area + "] " + text,
                                fmt::format("PRIORITY={}", journalPriority(msg.level)),
                                "SYSLOG_IDENTIFIER=replica", "REPLICA_LOGGER=" + area};
        iovec iov[std::size(fields)];
        for (std::size_t i = 0; i < std::size(fields); ++i) {
            iov[i] = {fields[i].data(), fields[i].size()};
        }
        if (native && sd_journal_sendv(iov, static_cast<int>(std::size(fields))) >= 0) {
            return;
        }
#endif
        const auto line = journalStreamLine(msg.level, area, text);
        std::fwrite(line.data(), 1, line.size(), stderr);
    }
    void flush_() override
    {
        std::fflush(stderr);
    }
};

bool stderrIsJournal()
{
    static const bool is = journalStreamIs(std::getenv("JOURNAL_STREAM"), 2);
    return is;
}

// Taps added to every logger, including those created later.
std::vector<spdlog::sink_ptr>& taps()
{
    static std::vector<spdlog::sink_ptr> t;
    return t;
}

bool isTap(const spdlog::sink_ptr& s)
{
    const auto& t = taps();
    return std::find(t.begin(), t.end(), s) != t.end();
}

// The level a logger's console shows: its own, or its console sink's when that is higher (a
// logger held open for a tap).
spdlog::level::level_enum consoleLevel(const spdlog::logger& l)
{
    for (const auto& s : l.sinks()) {
        if (!isTap(s)) {
            return std::max(s->level(), l.level());
        }
    }
    return l.level();
}

// Shows 'level' on the logger's console while the logger lets every tap's level through (a
// quieter console must not hide warnings from a recording). Under registryMutex().
void setLevelLocked(spdlog::logger& l, spdlog::level::level_enum level)
{
    auto open = level;
    for (const auto& t : taps()) {
        open = std::min(open, t->level());
    }
    for (const auto& s : l.sinks()) {
        if (!isTap(s)) {
            s->set_level(level);
        }
    }
    l.set_level(open);
}

// 'spec' has passed checkLogSpec.
void applySpec(const std::string& spec)
{
    for (const auto& item : specItems(spec)) {
        const auto level = *parseLevel(item.level);
        std::vector<std::shared_ptr<spdlog::logger>> loggers;
        if (!item.name) {
            for (const char* area : kAreas) {
                loggers.push_back(logger(area));
            }
        } else {
            loggers.push_back(logger(*item.name));
        }
        std::lock_guard lock(registryMutex());
        for (const auto& l : loggers) {
            setLevelLocked(*l, level);
        }
    }
}

// The process's warnings and errors (followLogs).
struct LogHistory {
    std::mutex mutex;
    std::deque<LoggedMessage> kept;
    std::vector<std::shared_ptr<LogFollower>> followers;
    std::shared_ptr<void> tap;
};

LogHistory& history()
{
    static LogHistory h;
    return h;
}

void startLogHistory()
{
    auto& h = history();
    {
        std::lock_guard lock(h.mutex);
        if (h.tap) {
            return;
        }
    }
    auto tap =
            tapLogs(spdlog::level::warn, [](spdlog::level::level_enum level,
                                            const std::string& area, const std::string& message) {
                auto& hist = history();
                const LoggedMessage m{std::chrono::steady_clock::now(), level, area, message};
                std::lock_guard lock(hist.mutex);
                hist.kept.push_back(m);
                if (hist.kept.size() > kLogHistoryLimit) {
                    hist.kept.pop_front();
                }
                for (const auto& f : hist.followers) {
                    (*f)(m);
                }
            });
    std::lock_guard lock(h.mutex);
    h.tap = std::move(tap);
}

} // namespace

std::shared_ptr<spdlog::logger> logger(const std::string& area)
{
    std::lock_guard lock(registryMutex());
    if (auto existing = spdlog::get(area)) {
        return existing;
    }
    std::shared_ptr<spdlog::logger> created;
    if (stderrIsJournal()) {
        // The journal stamps each line itself and files its priority: no time or level text.
        created = std::make_shared<spdlog::logger>(area, std::make_shared<JournalSink>());
        spdlog::initialize_logger(created);
    } else {
        created = spdlog::stderr_color_mt(area);
        auto formatter = std::make_unique<spdlog::pattern_formatter>();
        formatter->add_flag<PrintableMessage>('*').set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %*");
        created->set_formatter(std::move(formatter));
    }
    // An area first used after --log-level was applied follows the general level, not spdlog's
    // default (info): 'replay --log-level warn' must not print a late area's info lines.
    auto console = consoleLevel(*created);
    if (auto general = spdlog::get("replica"); general && general != created) {
        console = consoleLevel(*general);
    }
    for (const auto& t : taps()) {
        created->sinks().push_back(t);
    }
    setLevelLocked(*created, console);
    return created;
}

std::string checkLogSpec(const std::string& spec)
{
    for (const auto& item : specItems(spec)) {
        if (item.name && item.name->empty()) {
            return fmt::format("'{}' names no logger; write 'name=level', e.g. hal.tracker=debug",
                               item.text);
        }
        if (!parseLevel(item.level)) {
            return fmt::format("unknown log level '{}'; use one of trace, debug, info, warn, "
                               "error, critical, off (for all loggers, or per logger as "
                               "'hal.tracker=debug,rec=info')",
                               item.level);
        }
    }
    return {};
}

std::shared_ptr<void> tapLogs(spdlog::level::level_enum minLevel, LogTap tap)
{
    auto sink = std::make_shared<TapSink>(std::move(tap));
    sink->set_level(minLevel);
    {
        std::lock_guard lock(registryMutex());
        taps().push_back(sink);
        spdlog::apply_all([&](const std::shared_ptr<spdlog::logger>& l) {
            // A quieter console (--log-level error) must not hide warnings from the tap.
            const auto console = consoleLevel(*l);
            l->sinks().push_back(sink);
            setLevelLocked(*l, console);
        });
    }
    spdlog::sink_ptr held = sink;
    return std::shared_ptr<void>(nullptr, [held](void*) {
        std::lock_guard lock(registryMutex());
        auto& t = taps();
        t.erase(std::remove(t.begin(), t.end(), held), t.end());
        spdlog::apply_all([&](const std::shared_ptr<spdlog::logger>& l) {
            auto& s = l->sinks();
            s.erase(std::remove(s.begin(), s.end(), held), s.end());
        });
    });
}

std::shared_ptr<void> followLogs(LogFollower follower)
{
    auto& h = history();
    auto f = std::make_shared<LogFollower>(std::move(follower));
    {
        std::lock_guard lock(h.mutex);
        for (const auto& m : h.kept) {
            (*f)(m);
        }
        h.followers.push_back(f);
    }
    return std::shared_ptr<void>(nullptr, [f](void*) {
        auto& hist = history();
        std::lock_guard lock(hist.mutex);
        auto& v = hist.followers;
        v.erase(std::remove(v.begin(), v.end(), f), v.end());
    });
}

bool journalStreamIs(const char* journalStream, int fd)
{
    if (journalStream == nullptr) {
        return false;
    }
    unsigned long long device = 0;
    unsigned long long inode = 0;
    char end = 0;
    // Exactly "DEVICE:INODE", both decimal (systemd.exec(5)).
    if (std::sscanf(journalStream, "%llu:%llu%c", &device, &inode, &end) != 2) {
        return false;
    }
    struct stat st {
    };
    if (fstat(fd, &st) != 0) {
        return false;
    }
    return static_cast<unsigned long long>(st.st_dev) == device &&
           static_cast<unsigned long long>(st.st_ino) == inode;
}

int journalPriority(spdlog::level::level_enum level)
{
    switch (level) {
    case spdlog::level::critical:
        return 2;
    case spdlog::level::err:
        return 3;
    case spdlog::level::warn:
        return 4;
    case spdlog::level::info:
        return 6;
    default:
        return 7;
    }
}

std::string journalStreamLine(spdlog::level::level_enum level,
                              const std::string& area,
                              const std::string& message)
{
    return fmt::format("<{}>[{}] {}\n", journalPriority(level), area, message);
}

void setupLogging(const std::string& spec, bool fromCommandLine)
{
    for (const char* area : kAreas) {
        logger(area);
    }
    startLogHistory();
    // The default, then the environment, then the command line: the command line wins.
    applySpec("info");
    if (const char* env = std::getenv("REPLICA_LOG"); env != nullptr && checkLogSpec(env).empty()) {
        applySpec(env);
    }
    if (fromCommandLine) {
        applySpec(spec);
    }
}

} // namespace replica::platform
