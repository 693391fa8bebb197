// Measuring a panel patch by patch.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/output_file.h>
#include <pipeline/offline/display/cgats.h>
#include <platform/cli/commands.h>
#include <platform/cli/display_patches.h>
#include <platform/image/png_writer.h>
#include <platform/logging.h>
#include <platform/output/output.h>

namespace replica::platform {
namespace {

namespace pd = pipeline::display;

// The default set: black three times, R, G and B ramps every 'step' counts and full drive (read
// 'fullRepeats' times: their mean sets the primary's scale, and with it every count near the
// top), white twice, and pseudo-random colours: what 'display fit' needs, in the order it is
// shown. At the defaults (step 3, 10, 60 colours) 347 patches: docs/display.md says why.
std::vector<glm::dvec3>
defaultSet(int bits, int step, int fullRepeats, int colours, std::uint64_t seed)
{
    const double maxCount = std::ldexp(1.0, bits) - 1.0;
    std::vector<glm::dvec3> p(3, glm::dvec3(0.0));
    for (int c = 0; c < 3; ++c) {
        for (double v = step; v < maxCount; v += step) {
            glm::dvec3 q(0.0);
            q[c] = v;
            p.push_back(q);
        }
        for (int i = 0; i < std::max(fullRepeats, 1); ++i) {
            glm::dvec3 q(0.0);
            q[c] = maxCount;
            p.push_back(q);
        }
    }
    p.emplace_back(maxCount);
    p.emplace_back(maxCount);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < colours; ++i) {
        glm::dvec3 q;
        for (int c = 0; c < 3; ++c) {
            q[c] = std::floor(static_cast<double>(rng() >> 11) * 0x1.0p-53 * (maxCount + 1.0));
        }
        p.push_back(q);
    }
    return p;
}

// A subprocess with its stdin and stdout piped to us.
class Meter
{
public:
    static std::optional<Meter> start(const std::string& command)
    {
        // A meter that exits mid-run must not take us with it: a write to its closed stdin then
        // fails with EPIPE and is reported as the meter having ended.
        ::signal(SIGPIPE, SIG_IGN);
        int in[2];
        int out[2];
        if (::pipe(in) != 0 || ::pipe(out) != 0) {
            return std::nullopt;
        }
        const pid_t pid = ::fork();
        if (pid < 0) {
            return std::nullopt;
        }
        if (pid == 0) {
            ::dup2(in[0], 0);
            ::dup2(out[1], 1);
            ::close(in[1]);
            ::close(out[0]);
            ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
            ::_exit(127);
        }
        ::close(in[0]);
        ::close(out[1]);
        Meter m;
        m.pid_ = pid;
        m.toMeter_ = in[1];
        m.fromMeter_ = ::fdopen(out[0], "r");
        return m;
    }

    // Asks for one reading (a key press, as spotread takes it) and returns the XYZ of its
    // " Result is XYZ: X Y Z, ..." line; nullopt when the meter ends first (lastLine says what it
    // printed last).
    std::optional<glm::dvec3> read(std::string& lastLine)
    {
        if (::write(toMeter_, " ", 1) != 1) {
            return std::nullopt;
        }
        char buf[1024];
        while (std::fgets(buf, sizeof buf, fromMeter_) != nullptr) {
            std::string line(buf);
            while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) {
                line.pop_back();
            }
            if (!line.empty()) {
                lastLine = line;
            }
            const auto at = line.find("Result is XYZ:");
            double x = 0.0;
            double y = 0.0;
            double z = 0.0;
            if (at != std::string::npos &&
                std::sscanf(line.c_str() + at + 14, " %lf %lf %lf", &x, &y, &z) == 3) {
                return glm::dvec3(x, y, z);
            }
        }
        return std::nullopt;
    }

    void stop()
    {
        if (pid_ > 0) {
            [[maybe_unused]] const auto n = ::write(toMeter_, "q", 1);
            ::close(toMeter_);
            std::fclose(fromMeter_);
            int status = 0;
            ::waitpid(pid_, &status, 0);
            pid_ = -1;
        }
    }

private:
    pid_t pid_ = -1;
    int toMeter_ = -1;
    std::FILE* fromMeter_ = nullptr;
};

// 'display patches --make-set': the default set written as a .ti1.
int makeSetMain(const PatchesOptions& o)
{
    const auto set = defaultSet(o.bits, o.step, o.fullDriveRepeats, o.colours, o.seed);
    if (auto ok = writeOutputFile(o.makeSet, pd::ti1Text(set, o.bits, "Replica display patches"),
                                  "patch set");
        !ok) {
        logger("replica")->error("{}", ok.error().message);
        return kExitFailure;
    }
    fmt::print("patch set: {} ({} patches)\n", o.makeSet, set.size());
    return kExitOk;
}

// Whether the options fit together; the usage error logged where not.
bool usageOk(const PatchesOptions& o)
{
    auto log = logger("replica");
    const bool kms = o.output == "kms";
    if (o.output != "headless" && !kms) {
        log->error("display patches: --output is 'headless' (with --show-dir DIR) or 'kms', not "
                   "'{}'",
                   o.output);
        return false;
    }
    if (kms && !o.showDir.empty()) {
        log->error("display patches: --show-dir is the headless display's; with --output kms the "
                   "patch is shown on the panel");
        return false;
    }
    if (o.set.empty() || o.out.empty() || (!kms && o.showDir.empty())) {
        log->error("display patches: give SET.ti1, --out READINGS.ti3 and --show-dir DIR or "
                   "--output kms (or --make-set SET.ti1)");
        return false;
    }
    return true;
}

// The patch set, and the readings already taken: they must be of the set's first patches, in
// order (resume).
struct PatchSession {
    std::vector<glm::dvec3> set;
    std::vector<pd::Measurement> readings;
};

std::optional<PatchSession> loadSession(const PatchesOptions& o)
{
    auto log = logger("replica");
    // The bounded reader: a FIFO, /dev/zero or a directory is refused in one line.
    auto text = readInputFile(o.set, kMaxCsvBytes, "patch set (.ti1)");
    if (!text) {
        log->error("{}", text.error().message);
        return std::nullopt;
    }
    auto set = pd::parseTi1(*text, o.set, o.bits);
    if (!set) {
        log->error("{}", set.error().message);
        return std::nullopt;
    }
    PatchSession session{std::move(*set), {}};
    if (!std::filesystem::exists(o.out)) {
        return session;
    }
    auto done = pd::loadMeasurements(o.out, o.bits);
    if (!done) {
        log->error("{} (delete it to start again)", done.error().message);
        return std::nullopt;
    }
    for (std::size_t i = 0; i < done->rows.size(); ++i) {
        if (i >= session.set.size() || done->rows[i].counts != session.set[i]) {
            log->error("{}:{}: reading {} is not of patch {} of {}: a different set? (delete "
                       "it to start again)",
                       o.out, done->rows[i].line, i + 1, i + 1, o.set);
            return std::nullopt;
        }
    }
    session.readings = done->rows;
    fmt::print("resuming at patch {} of {} ({} readings in {})\n", session.readings.size() + 1,
               session.set.size(), session.readings.size(), o.out);
    return session;
}

// Where the patches are shown: the panel, through the appliance's KMS output (CPU copies into
// dumb buffers: a patch is one flat colour, drawn here, with no renderer behind it), or a
// full-frame PNG of the patch (8-bit) and its counts in --show-dir for the headless display.
class PatchScreen
{
public:
    bool open(const PatchesOptions& o)
    {
        o_ = &o;
        if (o.output != "kms") {
            std::filesystem::create_directories(o.showDir);
            return true;
        }
        auto log = logger("replica");
        KmsOptions ko;
        ko.device = o.kmsDevice;
        ko.connector = o.kmsConnector;
        ko.path = "dumb";
        auto out = createKmsOutput(ko);
        if (!out) {
            log->error("{}: cannot show patches on the panel: {}; without the panel: --output "
                       "headless --show-dir DIR",
                       o.kmsDevice, out.error().message);
            return false;
        }
        panel_ = std::move(*out);
        mode_ = panel_->display().value_or(DisplayInfo{});
        if (mode_.width <= 0 || mode_.height <= 0) {
            log->error("{}: the KMS output reports no mode", o.kmsDevice);
            return false;
        }
        fmt::print("showing patches on {} {}x{}\n", mode_.connector, mode_.width, mode_.height);
        return true;
    }

    // Shows patch i (counts c) of 'total'; 'kept' readings are in --out so far.
    bool show(const glm::dvec3& c, std::size_t i, std::size_t total, std::size_t kept) const
    {
        const PatchesOptions& o = *o_;
        const double maxCount = std::ldexp(1.0, o.bits) - 1.0;
        const int width = panel_ ? mode_.width : 64;
        const int height = panel_ ? mode_.height : 64;
        std::array<std::uint8_t, 4> px{0, 0, 0, 255};
        for (int k = 0; k < 3; ++k) {
            px[static_cast<std::size_t>(k)] =
                    static_cast<std::uint8_t>(std::lround(c[k] / maxCount * 255.0));
        }
        std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) *
                                       static_cast<std::size_t>(height) * 4);
        for (std::size_t p = 0; p < rgba.size(); p += 4) {
            std::copy(px.begin(), px.end(), rgba.begin() + static_cast<std::ptrdiff_t>(p));
        }
        auto log = logger("replica");
        if (panel_) {
            if (auto ok = panel_->present(DisplayFrame{width, height, rgba, 0}); !ok) {
                log->error("{}: cannot show patch {} of {}: {}; {} readings kept in {}",
                           o.kmsDevice, i + 1, total, ok.error().message, kept, o.out);
                return false;
            }
            return true;
        }
        const auto dir = std::filesystem::path(o.showDir);
        if (auto ok = writePng(dir / "patch.png", width, height, rgba);
            !ok || !writeOutputFile(dir / "patch.txt", fmt::format("{} {} {}\n", c.x, c.y, c.z),
                                    "patch shown")) {
            log->error("{}: cannot show the patch", o.showDir);
            return false;
        }
        return true;
    }

private:
    const PatchesOptions* o_ = nullptr;
    std::unique_ptr<Output> panel_;
    DisplayInfo mode_;
};

// One reading typed as X Y Z: the reading, std::nullopt at the end of input ('stopped' set), or
// std::nullopt after logging what is wrong with the line.
std::optional<glm::dvec3> readTyped(const glm::dvec3& c,
                                    std::size_t i,
                                    std::size_t total,
                                    std::size_t kept,
                                    const std::string& out,
                                    bool& stopped)
{
    fmt::print("patch {}/{} {},{},{}: X Y Z (cd/m^2)? ", i + 1, total, c.x, c.y, c.z);
    std::fflush(stdout);
    std::string line;
    if (!std::getline(std::cin, line)) {
        fmt::print("\nstopped: {} of {} readings in {}; run again to resume\n", kept, total, out);
        stopped = true;
        return std::nullopt;
    }
    double x = 0.0;
    double y = 0.0;
    double z = 0.0;
    char extra = 0;
    if (std::sscanf(line.c_str(), " %lf %lf %lf %c", &x, &y, &z, &extra) != 3 ||
        !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        logger("replica")->error("patch {}: '{}' is not three numbers X Y Z; {} readings kept in "
                                 "{}",
                                 i + 1, line, kept, out);
        return std::nullopt;
    }
    return glm::dvec3(x, y, z);
}

} // namespace

int patchesMain(const PatchesOptions& o)
{
    auto log = logger("replica");
    if (!o.makeSet.empty()) {
        return makeSetMain(o);
    }
    if (!usageOk(o)) {
        return kExitUsage;
    }
    auto session = loadSession(o);
    if (!session) {
        return kExitFailure;
    }
    const auto& set = session->set;
    auto& readings = session->readings;
    PatchScreen screen;
    if (!screen.open(o)) {
        return kExitFailure;
    }
    std::optional<Meter> meter;
    if (!o.spotread.empty()) {
        meter = Meter::start(o.spotread);
        if (!meter) {
            log->error("cannot start the meter '{}'", o.spotread);
            return kExitFailure;
        }
    }
    for (std::size_t i = readings.size(); i < set.size(); ++i) {
        const glm::dvec3 c = set[i];
        if (!screen.show(c, i, set.size(), readings.size())) {
            return kExitFailure;
        }
        if (o.settleMs > 0) {
            std::this_thread::sleep_for(std::chrono::milliseconds(o.settleMs));
        }
        std::optional<glm::dvec3> xyz;
        if (meter) {
            std::string last;
            xyz = meter->read(last);
            if (!xyz) {
                meter->stop();
                log->error("the meter ended before reading patch {} of {} ({}): {} readings kept "
                           "in {}; run again to resume",
                           i + 1, set.size(), last.empty() ? "no output" : last, readings.size(),
                           o.out);
                return kExitFailure;
            }
        } else {
            bool stopped = false;
            xyz = readTyped(c, i, set.size(), readings.size(), o.out, stopped);
            if (!xyz) {
                return stopped ? kExitOk : kExitFailure;
            }
        }
        pd::Measurement m;
        m.counts = c;
        m.xyz = *xyz;
        readings.push_back(m);
        if (auto ok = writeOutputFile(
                    o.out, pd::ti3Text(readings, o.bits, "Replica display patches"), "readings");
            !ok) {
            log->error("{}", ok.error().message);
            return kExitFailure;
        }
        fmt::print("[{}/{}] {},{},{} -> XYZ {:.4f} {:.4f} {:.4f}\n", i + 1, set.size(), c.x, c.y,
                   c.z, xyz->x, xyz->y, xyz->z);
    }
    if (meter) {
        meter->stop();
    }
    fmt::print("readings: {} ({} patches); fit with 'replica display fit {} --out PROFILE'\n",
               o.out, readings.size(), o.out);
    return kExitOk;
}

} // namespace replica::platform
