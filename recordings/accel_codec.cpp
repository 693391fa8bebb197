// The accelerometer's samples on /hal/accel and their raw sysfs readings on /replica/raw/accel
// (format 5): JSON payloads, schemas and codec.
#include <recordings/codec_json.h>

namespace replica::recordings {

std::optional<std::string> encodeAccel(const hal::AccelSample& s)
{
    if (!finite(s.gravity)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs}, {"seq", s.sequence}, {"gravity", vec3(s.gravity)}}.dump();
}

hal::AccelSample decodeAccel(const json& j)
{
    hal::AccelSample s;
    s.timestampNs = integerField<std::int64_t>(j, "t");
    s.sequence = integerField<std::uint32_t>(j, "seq");
    s.gravity = vec3From(j.at("gravity"));
    return s;
}

std::pair<std::string, std::string> accelSchema()
{
    return {"replica.AccelSample",
            schemaText("replica.AccelSample", "Gravity in the display's device frame (m/s^2)",
                       std::string(kTimeSeqProps) + R"(, "gravity": )" + std::string(kVec3Schema),
                       R"("t", "seq", "gravity")")};
}

std::optional<std::string> encodeRawAccel(const hal::AccelSample& s)
{
    if (!s.raw || !finite(s.raw->raw) || !finite(s.raw->scale) || !finite(s.raw->offset)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs},    {"seq", s.sequence},       {"raw", s.raw->raw},
                {"scale", s.raw->scale}, {"offset", s.raw->offset}, {"axes", s.raw->axes}}
            .dump();
}

std::pair<std::uint32_t, std::shared_ptr<hal::RawAccelInput>> decodeRawAccel(const json& j)
{
    auto r = std::make_shared<hal::RawAccelInput>();
    const std::uint32_t seq = j.at("seq");
    (void)j.at("t").get<std::int64_t>();
    r->raw = j.at("raw");
    r->scale = j.at("scale");
    r->offset = j.at("offset");
    r->axes = j.at("axes");
    return {seq, std::move(r)};
}

std::pair<std::string, std::string> rawAccelSchema()
{
    return {"replica.RawAccel",
            schemaText("replica.RawAccel",
                       "Raw in, processed out: the accelerometer's sysfs reading for accel "
                       "sample seq; gravity = -mounting((raw + offset) * scale)",
                       std::string(kTimeSeqProps) + R"(,
    "raw": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
      "description": "in_accel_{x,y,z}_raw"},
    "scale": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
    "offset": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
    "axes": {"type": "string", "description": "mounting: sensor axis for the panel's x, y, z"})",
                       R"("t", "seq", "raw", "scale", "offset", "axes")")};
}

SampleCodec<hal::AccelSample> accelCodec()
{
    SampleCodec<hal::AccelSample> c;
    c.encode = encodeAccel;
    c.decode = decodeAccel;
    c.encodeRaw = [](const hal::AccelSample& a, std::uint16_t channel,
                     RawCodecState<hal::AccelSample>::Writer&, const DeviceEmitter& emit) {
        if (!a.raw) {
            return;
        }
        if (auto raw = encodeRawAccel(a)) {
            emit.message(channel, a.timestampNs, std::move(*raw));
        } else {
            emit.rejectRaw();
        }
    };
    c.decodeRaw = [](const json& j, RawCodecState<hal::AccelSample>::Reader& st) {
        auto [seq, raw] = decodeRawAccel(j);
        st.raw[seq] = std::move(raw);
        return true;
    };
    c.attachRaw = [](std::vector<hal::AccelSample>& samples,
                     RawCodecState<hal::AccelSample>::Reader& st) {
        return attachRawBySequence(samples, st.raw);
    };
    c.hasRaw = [](const hal::AccelSample& a) { return a.raw != nullptr; };
    return c;
}

} // namespace replica::recordings
