// Encoding and decoding of the MCAP records that both the writer and the reader handle.
#include <recordings/mcap/records.h>

namespace replica::recordings::mcap {

std::string record(Op op, std::string_view content)
{
    ByteWriter w;
    w.u8(static_cast<std::uint8_t>(op));
    w.u64(content.size());
    w.raw(content);
    return std::move(w.bytes());
}

std::string encodeSchema(const Schema& s)
{
    ByteWriter w;
    w.u16(s.id);
    w.str(s.name);
    w.str(s.encoding);
    w.str(s.data);
    return record(Op::Schema, w.bytes());
}

namespace {

std::string stringMap(const std::map<std::string, std::string>& m)
{
    ByteWriter map;
    for (const auto& [k, v] : m) {
        map.str(k);
        map.str(v);
    }
    return std::move(map.bytes());
}

std::optional<std::map<std::string, std::string>> readStringMap(std::string_view bytes)
{
    ByteReader map(bytes);
    std::map<std::string, std::string> out;
    while (map.remaining() > 0 && !map.failed()) {
        std::string k(map.str());
        std::string v(map.str());
        out[k] = v;
    }
    if (map.failed()) {
        return std::nullopt;
    }
    return out;
}

} // namespace

std::string encodeMetadata(const Metadata& m)
{
    ByteWriter w;
    w.str(m.name);
    w.str(stringMap(m.metadata));
    return record(Op::Metadata, w.bytes());
}

std::optional<Metadata> decodeMetadata(std::string_view content)
{
    ByteReader r(content);
    Metadata m;
    m.name = r.str();
    const auto bytes = r.str();
    if (r.failed()) {
        return std::nullopt;
    }
    auto map = readStringMap(bytes);
    if (!map) {
        return std::nullopt;
    }
    m.metadata = std::move(*map);
    return m;
}

std::string encodeChannel(const Channel& c)
{
    const std::string map = stringMap(c.metadata);
    ByteWriter w;
    w.u16(c.id);
    w.u16(c.schemaId);
    w.str(c.topic);
    w.str(c.messageEncoding);
    w.str(map);
    return record(Op::Channel, w.bytes());
}

std::string encodeMessage(const Message& m)
{
    ByteWriter w;
    w.u16(m.channelId);
    w.u32(m.sequence);
    w.u64(m.logTime);
    w.u64(m.publishTime);
    w.raw(m.data);
    return record(Op::Message, w.bytes());
}

std::optional<Schema> decodeSchema(std::string_view content)
{
    ByteReader r(content);
    Schema s;
    s.id = r.u16();
    s.name = r.str();
    s.encoding = r.str();
    s.data = r.str();
    if (r.failed()) {
        return std::nullopt;
    }
    return s;
}

std::optional<Channel> decodeChannel(std::string_view content)
{
    ByteReader r(content);
    Channel c;
    c.id = r.u16();
    c.schemaId = r.u16();
    c.topic = r.str();
    c.messageEncoding = r.str();
    const auto bytes = r.str();
    if (r.failed()) {
        return std::nullopt;
    }
    auto map = readStringMap(bytes);
    if (!map) {
        return std::nullopt;
    }
    c.metadata = std::move(*map);
    return c;
}

std::optional<Message> decodeMessage(std::string_view content)
{
    ByteReader r(content);
    Message m;
    m.channelId = r.u16();
    m.sequence = r.u32();
    m.logTime = r.u64();
    m.publishTime = r.u64();
    m.data = r.rest();
    if (r.failed()) {
        return std::nullopt;
    }
    return m;
}

} // namespace replica::recordings::mcap
