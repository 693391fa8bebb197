// A first, minimal MCAP recording: unchunked messages with JSON payloads and JSON Schemas, written
// synchronously, and a linear reader. (The hardened writer -- chunks, CRCs, summary, background
// thread -- replaces this file.)
#include <cstring>
#include <fstream>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <recordings/recording.h>

namespace replica::recordings {
namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

void putU16(std::string& b, std::uint16_t v)
{
    for (int i = 0; i < 2; ++i) {
        b.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    }
}
void putU32(std::string& b, std::uint32_t v)
{
    for (int i = 0; i < 4; ++i) {
        b.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    }
}
void putU64(std::string& b, std::uint64_t v)
{
    for (int i = 0; i < 8; ++i) {
        b.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    }
}
void putString(std::string& b, const std::string& s)
{
    putU32(b, static_cast<std::uint32_t>(s.size()));
    b += s;
}

std::string record(std::uint8_t op, const std::string& content)
{
    std::string r;
    r.push_back(static_cast<char>(op));
    putU64(r, content.size());
    return r + content;
}

const char* const kTopics[] = {"/replica/session", "/hal/spectrometer", "/hal/tracker",
                               "/hal/accel", "/replica/frame"};

nlohmann::json deviceJson(const hal::DeviceInfo& d)
{
    return {{"model", d.model},
            {"serial", d.serial},
            {"firmware", d.firmware},
            {"source", hal::toString(d.kind)}};
}

hal::DeviceInfo deviceFromJson(const nlohmann::json& j)
{
    hal::DeviceInfo d{j.at("model"), j.at("serial"), j.at("firmware"), hal::SourceKind::Sim};
    const std::string k = j.at("source");
    d.kind = k == "live"     ? hal::SourceKind::Live
             : k == "replay" ? hal::SourceKind::Replay
                             : hal::SourceKind::Sim;
    return d;
}

std::string vec3(const glm::dvec3& v)
{
    return nlohmann::json{{"x", v.x}, {"y", v.y}, {"z", v.z}}.dump();
}

class BasicWriter final : public RecordingWriter
{
public:
    explicit BasicWriter(std::ofstream out) : out_(std::move(out)) {}
    ~BasicWriter() override { (void)close(); }

    void begin(const SessionInfo& s)
    {
        out_.write(reinterpret_cast<const char*>(kMagic), 8);
        std::string h;
        putString(h, "");
        putString(h, fmt::format("replica {} (format {})", s.softwareVersion, kFormatVersion));
        out_ << record(0x01, h);
        for (std::uint16_t id = 1; id <= 5; ++id) {
            std::string schema;
            putU16(schema, id);
            putString(schema, kTopics[id - 1]);
            putString(schema, "jsonschema");
            putString(schema, R"({"type":"object"})");
            out_ << record(0x03, schema);
            std::string ch;
            putU16(ch, id);
            putU16(ch, id);
            putString(ch, kTopics[id - 1]);
            putString(ch, "json");
            putU32(ch, 0);
            out_ << record(0x04, ch);
        }
        nlohmann::json j{{"format_version", kFormatVersion},
                         {"software", s.softwareVersion},
                         {"config", s.configJson},
                         {"booth", s.boothModel},
                         {"scene", s.scene},
                         {"display_profile", s.displayProfile},
                         {"wall_clock_start_ns", s.wallClockStartNs},
                         {"spectrometer", deviceJson(s.spectrometer)},
                         {"tracker", deviceJson(s.tracker)},
                         {"accel", deviceJson(s.accel)}};
        message(1, 0, j.dump());
    }

    void write(const hal::SpectrumSample& s) override
    {
        nlohmann::json j{{"t", s.timestampNs},
                         {"seq", s.sequence},
                         {"integration_time_us", s.integrationTimeUs},
                         {"counts", s.counts},
                         {"wavelength_coeffs", s.wavelengthCoeffs},
                         {"nonlinearity_coeffs", s.nonlinearityCoeffs},
                         {"saturated", s.saturated}};
        message(2, s.timestampNs, j.dump());
    }
    void write(const hal::PoseSample& s) override
    {
        message(3, s.timestampNs,
                fmt::format(R"({{"t":{},"seq":{},"tracked":{},"eye":{}}})", s.timestampNs,
                            s.sequence, s.tracked, vec3(s.eyeTrackerM)));
    }
    void write(const hal::AccelSample& s) override
    {
        message(4, s.timestampNs,
                fmt::format(R"({{"t":{},"seq":{},"gravity":{}}})", s.timestampNs, s.sequence,
                            vec3(s.gravity)));
    }
    void write(const FrameRecord& f) override
    {
        nlohmann::json j{{"frame", f.frameIndex}, {"tick_ns", f.tickNs}};
        if (f.spectrumSequence) {
            j["spectrum_seq"] = *f.spectrumSequence;
        }
        if (f.poseSequence) {
            j["pose_seq"] = *f.poseSequence;
        }
        if (f.accelSequence) {
            j["accel_seq"] = *f.accelSequence;
        }
        message(5, f.tickNs, j.dump());
    }
    Expected<void> close() override
    {
        if (closed_) {
            return {};
        }
        closed_ = true;
        std::string dataEnd;
        putU32(dataEnd, 0);
        out_ << record(0x0F, dataEnd);
        std::string footer;
        putU64(footer, 0);
        putU64(footer, 0);
        putU32(footer, 0);
        out_ << record(0x02, footer);
        out_.write(reinterpret_cast<const char*>(kMagic), 8);
        out_.flush();
        if (!out_) {
            return makeError(ErrorCode::Io, "recording: writing failed (disk full?)");
        }
        return {};
    }

private:
    void message(std::uint16_t channel, std::int64_t t, const std::string& payload)
    {
        std::string m;
        putU16(m, channel);
        putU32(m, seq_[channel]++);
        putU64(m, static_cast<std::uint64_t>(t));
        putU64(m, static_cast<std::uint64_t>(t));
        out_ << record(0x05, m + payload);
    }

    std::ofstream out_;
    std::map<std::uint16_t, std::uint32_t> seq_;
    bool closed_ = false;
};

std::uint64_t getU(const std::string& b, std::size_t at, int bytes)
{
    std::uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) {
        v = (v << 8) | static_cast<std::uint8_t>(b[at + static_cast<std::size_t>(i)]);
    }
    return v;
}

glm::dvec3 vec3From(const nlohmann::json& j)
{
    return {j.at("x").get<double>(), j.at("y").get<double>(), j.at("z").get<double>()};
}

} // namespace

Expected<std::unique_ptr<RecordingWriter>>
RecordingWriter::create(const std::filesystem::path& path, const SessionInfo& session)
{
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: cannot create recording (is the directory writable?)",
                                     path.string()));
    }
    auto w = std::make_unique<BasicWriter>(std::move(out));
    w->begin(session);
    return std::unique_ptr<RecordingWriter>(std::move(w));
}

Expected<Recording> readRecording(const std::filesystem::path& path)
{
    const std::string name = path.string();
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        return makeError(ErrorCode::NotFound, fmt::format("{}: no such recording", name));
    }
    std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (b.empty()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: file is empty, not a recording", name));
    }
    if (b.size() < 8 || std::memcmp(b.data(), kMagic, 8) != 0) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: not an MCAP recording (bad magic bytes)", name));
    }
    Recording rec;
    bool haveSession = false;
    std::size_t at = 8;
    try {
        while (at + 9 <= b.size()) {
            const auto op = static_cast<std::uint8_t>(b[at]);
            const std::uint64_t len = getU(b, at + 1, 8);
            if (len > b.size() - at - 9) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}: record at byte {} runs past the end of the file "
                                             "(truncated?)",
                                             name, at));
            }
            const std::size_t body = at + 9;
            if (op == 0x05) {
                const auto channel = static_cast<std::uint16_t>(getU(b, body, 2));
                const auto j = nlohmann::json::parse(b.substr(body + 22, len - 22));
                if (channel == 1) {
                    rec.formatVersion = j.at("format_version");
                    rec.session.softwareVersion = j.at("software");
                    rec.session.configJson = j.at("config");
                    rec.session.boothModel = j.at("booth");
                    rec.session.scene = j.at("scene");
                    rec.session.displayProfile = j.at("display_profile");
                    rec.session.wallClockStartNs = j.at("wall_clock_start_ns");
                    rec.session.spectrometer = deviceFromJson(j.at("spectrometer"));
                    rec.session.tracker = deviceFromJson(j.at("tracker"));
                    rec.session.accel = deviceFromJson(j.at("accel"));
                    haveSession = true;
                } else if (channel == 2) {
                    hal::SpectrumSample s;
                    s.timestampNs = j.at("t");
                    s.sequence = j.at("seq");
                    s.integrationTimeUs = j.at("integration_time_us");
                    s.counts = j.at("counts").get<std::vector<std::uint16_t>>();
                    s.wavelengthCoeffs = j.at("wavelength_coeffs");
                    s.nonlinearityCoeffs = j.at("nonlinearity_coeffs");
                    s.saturated = j.at("saturated");
                    rec.spectra.push_back(std::move(s));
                } else if (channel == 3) {
                    hal::PoseSample s;
                    s.timestampNs = j.at("t");
                    s.sequence = j.at("seq");
                    s.tracked = j.at("tracked");
                    s.eyeTrackerM = vec3From(j.at("eye"));
                    rec.poses.push_back(s);
                } else if (channel == 4) {
                    hal::AccelSample s;
                    s.timestampNs = j.at("t");
                    s.sequence = j.at("seq");
                    s.gravity = vec3From(j.at("gravity"));
                    rec.accel.push_back(s);
                } else if (channel == 5) {
                    FrameRecord f;
                    f.frameIndex = j.at("frame");
                    f.tickNs = j.at("tick_ns");
                    if (j.contains("spectrum_seq")) {
                        f.spectrumSequence = j.at("spectrum_seq").get<std::uint32_t>();
                    }
                    if (j.contains("pose_seq")) {
                        f.poseSequence = j.at("pose_seq").get<std::uint32_t>();
                    }
                    if (j.contains("accel_seq")) {
                        f.accelSequence = j.at("accel_seq").get<std::uint32_t>();
                    }
                    rec.frames.push_back(f);
                }
            }
            at = body + len;
            if (op == 0x0F) {
                break;
            }
        }
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: damaged message at byte {}: {}", name, at, e.what()));
    }
    if (!haveSession) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: MCAP file without a replica session; not a replica recording",
                            name));
    }
    return rec;
}

} // namespace replica::recordings
