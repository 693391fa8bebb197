// Decoding a recording's messages, with every check the reader holds one message to: the one code
// path that 'replica inspect', 'replica replay' (readRecording) and 'replica recover' share, so
// that recover keeps exactly what the reader accepts. Internal to recordings/.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include <pipeline/base/expected.h>
#include <recordings/mcap/records.h>
#include <recordings/recording.h>

namespace replica::recordings::detail {

// Decodes a recording's messages into 'rec' by topic: the session, each device kind's samples by
// its topic and (format 5) its raw inputs by its raw topic, attached to their samples by sequence
// number once all are read. A message that fails a check is refused whole, with one sentence
// naming the file, the topic, the message's sequence and what is wrong.
class MessageDecoder
{
public:
    MessageDecoder(Recording& rec, const DeviceKinds& kinds, std::string name);

    Expected<void> decode(const std::string& topic, const mcap::Message& m);

    bool haveSession() const { return haveSession_; }

    // The raw inputs attached to their samples; those that matched none are counted.
    void attachRaw();

    // Drops what was decoded so far (samples, frames, raw inputs) and keeps what later messages
    // are checked against (the session, the last frame's tick, HID descriptors): recover checks
    // every message of a file of any size in bounded memory.
    void forget();

private:
    Expected<void> decodeSessionMessage(const std::string& topic, const nlohmann::json& j);
    Expected<void> decodeJson(const std::string& topic, const nlohmann::json& j);
    void decodeFrameMessage(const nlohmann::json& j);

    Recording& rec_;
    const DeviceKinds& kinds_;
    std::string name_;
    std::map<std::string, std::size_t> sampleTopics_, rawTopics_;
    std::vector<AnyReaderState> rawState_; // in the kinds' order, as rec_.devices
    std::uint64_t unusableRaw_ = 0;
    std::int64_t lastTickNs_ = 0; // the last frame's tick: frames never go back (nor before 0)
    bool haveSession_ = false;
};

} // namespace replica::recordings::detail
