// MCAP record vocabulary: opcodes, magic, and bounds-checked little-endian encoding and decoding.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace replica::recordings::mcap {

inline constexpr std::string_view kMagic{"\x89MCAP0\r\n", 8};
inline constexpr std::size_t kRecordPrefix = 9; // opcode + uint64 content length
// Footer = prefix + summary_start + summary_offset_start + summary_crc.
inline constexpr std::size_t kFooterRecordSize = kRecordPrefix + 20;

enum class Op : std::uint8_t {
    Header = 0x01,
    Footer = 0x02,
    Schema = 0x03,
    Channel = 0x04,
    Message = 0x05,
    Chunk = 0x06,
    MessageIndex = 0x07,
    ChunkIndex = 0x08,
    Attachment = 0x09,
    AttachmentIndex = 0x0A,
    Statistics = 0x0B,
    Metadata = 0x0C,
    MetadataIndex = 0x0D,
    SummaryOffset = 0x0E,
    DataEnd = 0x0F,
};

struct Schema {
    std::uint16_t id = 0;
    std::string name;
    std::string encoding;
    std::string data;
    bool operator==(const Schema&) const = default;
};

struct Channel {
    std::uint16_t id = 0;
    std::uint16_t schemaId = 0;
    std::string topic;
    std::string messageEncoding;
    std::map<std::string, std::string> metadata;
    bool operator==(const Channel&) const = default;
};

struct Message {
    std::uint16_t channelId = 0;
    std::uint32_t sequence = 0;
    std::uint64_t logTime = 0;
    std::uint64_t publishTime = 0;
    std::string data;
};

struct Metadata {
    std::string name;
    std::map<std::string, std::string> metadata;
    bool operator==(const Metadata&) const = default;
};

// Appends little-endian fields to a byte string.
class ByteWriter
{
public:
    void u8(std::uint8_t v) { out_.push_back(static_cast<char>(v)); }
    void u16(std::uint16_t v) { le(v, 2); }
    void u32(std::uint32_t v) { le(v, 4); }
    void u64(std::uint64_t v) { le(v, 8); }
    void str(std::string_view s)
    {
        u32(static_cast<std::uint32_t>(s.size()));
        out_.append(s);
    }
    void raw(std::string_view s) { out_.append(s); }
    std::string& bytes() { return out_; }

private:
    void le(std::uint64_t v, int n)
    {
        for (int i = 0; i < n; ++i) {
            out_.push_back(static_cast<char>((v >> (8 * i)) & 0xffU));
        }
    }
    std::string out_;
};

// Reads little-endian fields from a byte range; every read is checked, a short read sets failed().
class ByteReader
{
public:
    explicit ByteReader(std::string_view in) : in_(in) {}
    std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
    std::uint16_t u16() { return static_cast<std::uint16_t>(le(2)); }
    std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
    std::uint64_t u64() { return le(8); }
    std::string_view bytes(std::uint64_t n)
    {
        if (failed_ || n > in_.size() - at_) {
            failed_ = true;
            return {};
        }
        auto s = in_.substr(at_, static_cast<std::size_t>(n));
        at_ += static_cast<std::size_t>(n);
        return s;
    }
    std::string_view str() { return bytes(u32()); }
    std::string_view rest() { return bytes(in_.size() - at_); }
    bool failed() const { return failed_; }
    std::size_t position() const { return at_; }
    std::size_t remaining() const { return in_.size() - at_; }

private:
    std::uint64_t le(std::size_t n)
    {
        if (failed_ || n > in_.size() - at_) {
            failed_ = true;
            return 0;
        }
        std::uint64_t v = 0;
        for (std::size_t i = n; i-- > 0;) {
            v = (v << 8) | static_cast<std::uint8_t>(in_[at_ + i]);
        }
        at_ += n;
        return v;
    }
    std::string_view in_;
    std::size_t at_ = 0;
    bool failed_ = false;
};

// A whole record: opcode, content length, content.
std::string record(Op op, std::string_view content);

std::string encodeSchema(const Schema& s);
std::string encodeChannel(const Channel& c);
std::string encodeMessage(const Message& m);
std::string encodeMetadata(const Metadata& m);

// Decoders return nullopt when the content is too short or inconsistent.
std::optional<Schema> decodeSchema(std::string_view content);
std::optional<Channel> decodeChannel(std::string_view content);
std::optional<Message> decodeMessage(std::string_view content);
std::optional<Metadata> decodeMetadata(std::string_view content);

} // namespace replica::recordings::mcap
