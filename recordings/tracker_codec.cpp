// The head tracker's poses on /hal/tracker and their raw inputs on /replica/raw/tracker (format 5):
// JSON payloads, schemas and codec.
#include <stdexcept>

#include <fmt/format.h>

#include <recordings/codec_json.h>

namespace replica::recordings {
namespace {

// A report or descriptor larger than any HID device's (4096 bytes, the kernel's limit).
constexpr std::size_t kMaxRawBytes = 4096;

std::vector<std::uint8_t> rawBytes(const json& j)
{
    auto bytes = base64Decode(j.at("bytes").get<std::string>());
    if (bytes.size() > kMaxRawBytes) {
        throw std::out_of_range(fmt::format("{} raw bytes; a device report is at most {}",
                                            bytes.size(), kMaxRawBytes));
    }
    return bytes;
}

} // namespace

std::optional<std::string> encodePose(const hal::PoseSample& s)
{
    if (!finite(s.eyeTrackerM)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs},
                {"seq", s.sequence},
                {"tracked", s.tracked},
                {"eye", vec3(s.eyeTrackerM)}}
            .dump();
}

hal::PoseSample decodePose(const json& j)
{
    hal::PoseSample s;
    s.timestampNs = integerField<std::int64_t>(j, "t");
    s.sequence = integerField<std::uint32_t>(j, "seq");
    s.tracked = j.at("tracked");
    s.eyeTrackerM = vec3From(j.at("eye"));
    return s;
}

std::pair<std::string, std::string> poseSchema()
{
    return {"replica.TrackerPose",
            schemaText("replica.TrackerPose",
                       "The viewer's eye position in the tracker frame (m): x right, y up, z "
                       "towards the viewer",
                       std::string(kTimeSeqProps) + R"(, "tracked": {"type": "boolean"}, "eye": )" +
                               std::string(kVec3Schema),
                       R"("t", "seq", "tracked", "eye")")};
}

std::string encodeRawTrackerDescriptor(std::int64_t tNs,
                                       std::uint32_t id,
                                       const std::vector<std::uint8_t>& descriptor)
{
    return json{{"t", tNs},
                {"kind", "hid-descriptor"},
                {"descriptor", id},
                {"bytes", base64Encode(descriptor)}}
            .dump();
}

std::optional<std::string> encodeRawTracker(const hal::PoseSample& s, std::uint32_t descriptorId)
{
    if (!s.raw) {
        return std::nullopt;
    }
    const hal::RawTrackerInput& r = *s.raw;
    json j{{"t", r.arrivalNs}, {"seq", s.sequence}, {"bytes", base64Encode(r.bytes)}};
    if (r.kind == hal::RawTrackerInput::Kind::OpentrackDatagram) {
        if (!std::isfinite(r.zSign) || !finite(r.eyeOffsetHeadM)) {
            return std::nullopt;
        }
        j["kind"] = "opentrack";
        j["z_sign"] = r.zSign;
        j["eye_offset_head_m"] = vec3(r.eyeOffsetHeadM);
    } else {
        j["kind"] = "hid";
        j["descriptor"] = descriptorId;
        j["axes"] = r.axes;
        j["reanchor_ns"] = r.reanchorNs;
    }
    return j.dump();
}

RawTrackerMessage
decodeRawTracker(const json& j,
                 const std::map<std::uint32_t, std::shared_ptr<const std::vector<std::uint8_t>>>&
                         descriptors)
{
    RawTrackerMessage m;
    const std::string kind = j.at("kind");
    if (kind == "hid-descriptor") {
        m.descriptorId = j.at("descriptor").get<std::uint32_t>();
        m.descriptor = std::make_shared<const std::vector<std::uint8_t>>(rawBytes(j));
        return m;
    }
    auto r = std::make_shared<hal::RawTrackerInput>();
    m.sequence = j.at("seq");
    r->arrivalNs = j.at("t");
    r->bytes = rawBytes(j);
    if (kind == "opentrack") {
        r->kind = hal::RawTrackerInput::Kind::OpentrackDatagram;
        r->zSign = j.at("z_sign");
        r->eyeOffsetHeadM = vec3From(j.at("eye_offset_head_m"));
    } else if (kind == "hid") {
        r->kind = hal::RawTrackerInput::Kind::HidReport;
        const auto id = j.at("descriptor").get<std::uint32_t>();
        const auto it = descriptors.find(id);
        // A descriptor the file does not hold before the report (e.g. its chunk was lost and
        // 'replica recover' dropped it) leaves the report unusable: no raw input, not an error.
        if (it == descriptors.end()) {
            m.descriptorMissing = true;
            return m;
        }
        r->hidDescriptor = it->second;
        r->axes = j.at("axes");
        r->reanchorNs = j.at("reanchor_ns");
    } else {
        throw std::out_of_range("unknown raw tracker kind '" + kind + "'");
    }
    m.raw = std::move(r);
    return m;
}

std::pair<std::string, std::string> rawTrackerSchema()
{
    return {"replica.RawTracker",
            schemaText(
                    "replica.RawTracker",
                    "Raw in, processed out: what the head tracker sent for pose seq, before "
                    "processing, with the processing's parameters; or (kind hid-descriptor) "
                    "the report descriptor of one opening of a HID tracker",
                    R"json("t": {"type": "integer", "description": "session time (ns) the bytes arrived"},
    "seq": {"type": "integer", "description": "the pose on /hal/tracker made from them"},
    "kind": {"type": "string", "enum": ["opentrack", "hid", "hid-descriptor"]},
    "bytes": {"type": "string", "contentEncoding": "base64", "description":
      "opentrack: the 48-byte datagram; hid: the input report, report ID first when numbered; hid-descriptor: the report descriptor"},
    "descriptor": {"type": "integer", "description": "hid, hid-descriptor: which descriptor"},
    "z_sign": {"type": "number", "description": "opentrack: sign of z in the tracker frame"},
    "eye_offset_head_m": )json" +
                            std::string(kVec3Schema) +
                            R"json(, "axes": {"type": "string", "description": "hid: device axes to the tracker frame, e.g. x,-y,z"},
    "reanchor_ns": {"type": "integer", "description": "hid: device clock re-anchoring threshold"})json",
                    R"("t", "kind", "bytes")")};
}

SampleCodec<hal::PoseSample> poseCodec()
{
    SampleCodec<hal::PoseSample> c;
    c.encode = encodePose;
    c.decode = decodePose;
    c.encodeRaw = [](const hal::PoseSample& p, std::uint16_t channel,
                     RawCodecState<hal::PoseSample>::Writer& st, const DeviceEmitter& emit) {
        if (!p.raw) {
            return;
        }
        const auto& d = p.raw->hidDescriptor;
        if (p.raw->kind == hal::RawTrackerInput::Kind::HidReport && d &&
            d.get() != st.lastDescriptor.get()) {
            // A new opening of the device: its descriptor once, before its first report.
            st.lastDescriptor = d;
            ++st.descriptorId;
            emit.message(channel, p.raw->arrivalNs,
                         encodeRawTrackerDescriptor(p.raw->arrivalNs, st.descriptorId, *d));
        }
        if (auto raw = encodeRawTracker(p, st.descriptorId)) {
            emit.message(channel, p.raw->arrivalNs, std::move(*raw));
        } else {
            emit.rejectRaw();
        }
    };
    c.decodeRaw = [](const json& j, RawCodecState<hal::PoseSample>::Reader& st) {
        auto r = decodeRawTracker(j, st.descriptors);
        if (r.descriptorId) {
            st.descriptors[*r.descriptorId] = r.descriptor;
        } else if (r.descriptorMissing) {
            return false;
        } else {
            st.raw[r.sequence] = std::move(r.raw);
        }
        return true;
    };
    c.attachRaw = [](std::vector<hal::PoseSample>& poses,
                     RawCodecState<hal::PoseSample>::Reader& st) {
        return attachRawBySequence(poses, st.raw);
    };
    c.hasRaw = [](const hal::PoseSample& p) { return p.raw != nullptr; };
    return c;
}

} // namespace replica::recordings
