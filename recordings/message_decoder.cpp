// The reader's per-message decoding and checks (message_decoder.h).
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/json_limits.h>
#include <recordings/message_decoder.h>
#include <recordings/sample_codec.h>
#include <recordings/session_schema.h>

namespace replica::recordings::detail {
namespace {

// A thumbnail message (foxglove.CompressedImage): its PNG, tNs its Unix time until the reader
// places it on its frame.
ThumbnailRecord decodeThumbnailMessage(const nlohmann::json& j)
{
    ThumbnailRecord t;
    t.tNs = j.at("timestamp").at("sec").get<std::int64_t>() * 1'000'000'000 +
            j.at("timestamp").at("nsec").get<std::int64_t>();
    t.png = base64Decode(j.at("data").get<std::string>());
    return t;
}

} // namespace

MessageDecoder::MessageDecoder(Recording& rec, const DeviceKinds& kinds, std::string name)
    : rec_(rec), kinds_(kinds), name_(std::move(name))
{
    rec.devices.clear();
    for (std::size_t i = 0; i < kinds.size(); ++i) {
        const auto& n = kinds[i]->names();
        rec.devices.push_back({kinds[i], kinds[i]->emptySamples()});
        rawState_.push_back(kinds[i]->readerState());
        sampleTopics_[n.channel.topic] = i;
        if (n.rawChannel) {
            rawTopics_[n.rawChannel->topic] = i;
        }
    }
}

Expected<void> MessageDecoder::decode(const std::string& topic, const mcap::Message& m)
{
    if (m.data.size() > kMaxMessageBytes) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: {} message (sequence {}) of {} bytes; Replica's are "
                                     "at most {} KiB: not a recording Replica wrote",
                                     name_, topic, m.sequence, m.data.size(),
                                     kMaxMessageBytes >> 10));
    }
    if (auto ok = checkJsonLimits(
                m.data, fmt::format("{}: {} message (sequence {})", name_, topic, m.sequence));
        !ok) {
        return ok;
    }
    try {
        return decodeJson(topic, nlohmann::json::parse(m.data));
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: damaged {} message (sequence {}): {}",
                                                         name_, topic, m.sequence, e.what()));
    }
}

void MessageDecoder::attachRaw()
{
    rec_.unmatchedRaw = unusableRaw_;
    for (std::size_t i = 0; i < kinds_.size(); ++i) {
        rec_.unmatchedRaw += kinds_[i]->attachRaw(rec_.devices[i].samples, rawState_[i]);
    }
}

void MessageDecoder::forget()
{
    for (std::size_t i = 0; i < kinds_.size(); ++i) {
        rec_.devices[i].samples = kinds_[i]->emptySamples();
        kinds_[i]->forgetRawInputs(rawState_[i]);
    }
    rec_.frames.clear();
    rec_.displayDigests.clear();
    rec_.lights.clear();
    rec_.thumbnails.clear();
}

Expected<void> MessageDecoder::decodeSessionMessage(const std::string& topic,
                                                    const nlohmann::json& j)
{
    if (auto ok = validateJson(j, sessionSchema(), fmt::format("{}: {} message", name_, topic));
        !ok) {
        return ok;
    }
    if (haveSession_) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: a second {} message; a recording has one session: not "
                                     "a recording Replica wrote",
                                     name_, topic));
    }
    rec_.session = decodeSession(j, rec_.formatVersion, kinds_);
    // The run configuration is JSON inside the session's JSON: held to the same limits before
    // anything (replay, inspect --json) parses it.
    if (auto ok = checkJsonLimits(rec_.session.configJson,
                                  fmt::format("{}: run configuration", name_));
        !ok) {
        return ok;
    }
    haveSession_ = true;
    return {};
}

// Frames are written in the order the loop ticks: one whose tick is before the frame ahead of it
// (or before the session start) was not written by Replica, and replay could not pace it.
void MessageDecoder::decodeFrameMessage(const nlohmann::json& j)
{
    FrameRecord f = decodeFrame(j, kinds_);
    if (f.tickNs < lastTickNs_) {
        throw std::out_of_range(fmt::format("frame {} has tick_ns {}, before {} (the session start "
                                            "or the frame ahead of it): the frame channel is "
                                            "corrupt",
                                            f.frameIndex, f.tickNs, lastTickNs_));
    }
    lastTickNs_ = f.tickNs;
    rec_.frames.push_back(std::move(f));
}

Expected<void> MessageDecoder::decodeJson(const std::string& topic, const nlohmann::json& j)
{
    if (topic == kSessionTopic) {
        return decodeSessionMessage(topic, j);
    }
    if (auto k = sampleTopics_.find(topic); k != sampleTopics_.end()) {
        kinds_[k->second]->decode(j, rec_.devices[k->second].samples);
    } else if (auto rk = rawTopics_.find(topic); rk != rawTopics_.end()) { // format 5
        if (!kinds_[rk->second]->decodeRaw(j, rawState_[rk->second])) {
            ++unusableRaw_;
        }
    } else if (topic == kFrameTopic) {
        decodeFrameMessage(j);
    } else if (topic == kDisplayDigestTopic) { // format 4
        rec_.displayDigests.push_back(decodeDisplayDigest(j));
    } else if (topic == kLightTopic) { // format 4
        rec_.lights.push_back(decodeLight(j));
    } else if (topic == kThumbnailTopic) { // format 4
        rec_.thumbnails.push_back(decodeThumbnailMessage(j));
    } else if (topic == kRecorderTopic) {
        const auto r = decodeRecorderStatus(j, kinds_);
        rec_.droppedMessages = r.droppedTotal();
        rec_.rejectedNonFinite = r.rejectedNonFinite;
    }
    return {};
}

} // namespace replica::recordings::detail
