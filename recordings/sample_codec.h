// The channels of a Replica recording and the JSON encoding of each message (with its JSON Schema).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <hal/samples.h>
#include <recordings/mcap/records.h>
#include <recordings/recording.h>

namespace replica::recordings {

// Fixed channel ids (they never change within a format version; recover relies on that).
enum class ChannelId : std::uint16_t {
    Session = 1,
    Spectrometer = 2,
    Tracker = 3,
    Accel = 4,
    Frame = 5,
    Recorder = 6,
    LampSelector = 7, // format 3
    // Format 4: what was shown, for people (standard Foxglove schemas where one exists).
    DisplayDigest = 8,
    Thumbnail = 9,
    Transforms = 10,
    Eye = 11,
    Light = 12,
    Log = 13,
    // Format 5: raw in, processed out. What the devices gave before processing, beside the
    // processed samples on 3 and 4, so that 'replay --reprocess' can re-derive them.
    RawTracker = 14,
    RawAccel = 15,
    // The running appliance's error probe (not replayed; a reader skips it).
    ErrorProbe = 16,
};

inline constexpr std::string_view kSessionTopic = "/replica/session";
inline constexpr std::string_view kSpectrometerTopic = "/hal/spectrometer";
inline constexpr std::string_view kTrackerTopic = "/hal/tracker";
inline constexpr std::string_view kAccelTopic = "/hal/accel";
inline constexpr std::string_view kFrameTopic = "/replica/frame";
inline constexpr std::string_view kRecorderTopic = "/replica/recorder";
inline constexpr std::string_view kLampSelectorTopic = "/hal/lamp_selector";
inline constexpr std::string_view kDisplayDigestTopic = "/replica/display_digest";
inline constexpr std::string_view kThumbnailTopic = "/replica/thumbnail";
inline constexpr std::string_view kTransformsTopic = "/tf";
inline constexpr std::string_view kEyeTopic = "/replica/eye";
inline constexpr std::string_view kLightTopic = "/replica/light";
inline constexpr std::string_view kLogTopic = "/replica/log";
inline constexpr std::string_view kRawTrackerTopic = "/replica/raw/tracker";
inline constexpr std::string_view kRawAccelTopic = "/replica/raw/accel";
inline constexpr std::string_view kErrorProbeTopic = "/replica/error_probe";
// Foxglove frame ids of the transforms and poses.
inline constexpr std::string_view kBoothFrame = "booth";
inline constexpr std::string_view kPanelFrame = "panel";
inline constexpr std::string_view kTrackerFrame = "tracker";
inline constexpr std::string_view kEyeFrame = "eye";
// A copy of the session message kept in a Metadata record outside every chunk (key "session"), so
// that recover can restore the session when the first chunk is damaged.
inline constexpr std::string_view kSessionMetadataName = "replica.session";

// What the recorder itself reports on /replica/recorder: samples it could not write.
struct RecorderStatus {
    // DeviceNames::droppedKey -> samples of that device dropped (every kind the writer has).
    std::map<std::string, std::uint64_t> droppedDevices;
    std::uint64_t droppedFrames = 0;
    std::uint64_t droppedShown = 0;      // format 4: thumbnails, poses, light, log, display digests
    std::uint64_t rejectedNonFinite = 0; // samples refused because a value was NaN or infinite
    std::uint64_t queueCapacity = 0;
    std::uint64_t droppedTotal() const
    {
        std::uint64_t n = droppedFrames + droppedShown;
        for (const auto& [key, d] : droppedDevices) {
            n += d;
        }
        return n;
    }
};

// The schema and channel of every channel of the current format with these device kinds, in id
// order.
struct ChannelDefinition {
    mcap::Schema schema;
    mcap::Channel channel;
};
const std::vector<ChannelDefinition>& channelDefinitions(); // with deviceKinds()
std::vector<ChannelDefinition> channelDefinitions(const DeviceKinds& kinds);

// JSON Schema text of a replica.* message, and fragments the device schemas share.
std::string jsonSchemaText(const std::string& title,
                           const std::string& description,
                           const std::string& properties,
                           const std::string& required);
inline constexpr const char* kTimeSeqProps =
        R"("t": {"type": "integer", "description": "session time (ns) when the loop received it"},
    "seq": {"type": "integer", "description": "the device's own counter; gaps are drops"})";
inline constexpr const char* kVec3Schema =
        R"({"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"},
      "z": {"type": "number"}}, "required": ["x", "y", "z"]})";

// The codec of each device sample type (device_kinds.cpp names the devices that use them): the
// encoders and decoders below, and the channel schema.
SampleCodec<hal::SpectrumSample> spectrumCodec();
SampleCodec<hal::PoseSample> poseCodec();   // with the raw tracker input (format 5)
SampleCodec<hal::AccelSample> accelCodec(); // with the raw IIO reading (format 5)
SampleCodec<hal::LampSample> lampCodec();
std::pair<std::string, std::string> spectrumSchema(); // (name, JSON Schema text)
std::pair<std::string, std::string> poseSchema();
std::pair<std::string, std::string> accelSchema();
std::pair<std::string, std::string> lampSchema();
std::pair<std::string, std::string> rawTrackerSchema();
std::pair<std::string, std::string> rawAccelSchema();

// JSON payloads. Doubles are written in shortest round-trip form and parse back bit-identically;
// encoders return nullopt when a double is NaN or infinite (JSON cannot spell them), and the
// writer counts such samples as rejected instead of writing a value that would read back wrong.
std::string
encodeSession(const SessionInfo& s, int formatVersion, const DeviceKinds& kinds = deviceKinds());
std::optional<std::string> encodeSpectrum(const hal::SpectrumSample& s);
std::optional<std::string> encodePose(const hal::PoseSample& s);
std::optional<std::string> encodeAccel(const hal::AccelSample& s);
std::string encodeLamp(const hal::LampSample& s);
std::string encodeFrame(const FrameRecord& f, const DeviceKinds& kinds = deviceKinds());
std::string encodeRecorderStatus(const RecorderStatus& r);
// Format 4. wallStartNs turns session time into the foxglove timestamps {sec, nsec} (Unix time).
std::string encodeDisplayDigest(const DisplayDigestRecord& d);
std::string encodeThumbnail(const ThumbnailRecord& t, std::int64_t wallStartNs);
std::optional<std::string> encodeTransforms(const PosesRecord& p, std::int64_t wallStartNs);
std::optional<std::string> encodeEye(const PosesRecord& p, std::int64_t wallStartNs);
std::string encodeLight(const LightRecord& l);
std::string encodeLog(const LogRecord& l, std::int64_t wallStartNs);
std::optional<std::string> encodeErrorProbe(const ErrorProbeRecord& e);
std::string base64Encode(const std::vector<std::uint8_t>& bytes);
// Strict (padding required, no whitespace); throws std::out_of_range on anything else.
std::vector<std::uint8_t> base64Decode(const std::string& text);

// Format 5, /replica/raw/tracker: a HID report descriptor (once per opening of the device, before
// the first report read with it; 'id' numbers them within the recording) and each datagram or
// report that made a pose (seq: the pose's). Raw accel: the sysfs reading of each sample.
std::string encodeRawTrackerDescriptor(std::int64_t tNs,
                                       std::uint32_t id,
                                       const std::vector<std::uint8_t>& descriptor);
std::optional<std::string> encodeRawTracker(const hal::PoseSample& s, std::uint32_t descriptorId);
std::optional<std::string> encodeRawAccel(const hal::AccelSample& s);

// Decoders throw nlohmann::json exceptions on missing or mistyped fields.
SessionInfo decodeSession(const nlohmann::json& j,
                          int& formatVersion,
                          const DeviceKinds& kinds = deviceKinds());
hal::SpectrumSample decodeSpectrum(const nlohmann::json& j);
hal::PoseSample decodePose(const nlohmann::json& j);
hal::AccelSample decodeAccel(const nlohmann::json& j);
hal::LampSample decodeLamp(const nlohmann::json& j);
FrameRecord decodeFrame(const nlohmann::json& j, const DeviceKinds& kinds = deviceKinds());
RecorderStatus decodeRecorderStatus(const nlohmann::json& j,
                                    const DeviceKinds& kinds = deviceKinds());
DisplayDigestRecord decodeDisplayDigest(const nlohmann::json& j);
LightRecord decodeLight(const nlohmann::json& j);
// A raw tracker message: either a descriptor (returned in 'descriptor' with its id) or the raw
// input of pose 'sequence' (its HID descriptor looked up in 'descriptors' by id).
struct RawTrackerMessage {
    std::uint32_t sequence = 0;
    std::shared_ptr<hal::RawTrackerInput> raw; // null for a descriptor message
    std::optional<std::uint32_t> descriptorId;
    std::shared_ptr<const std::vector<std::uint8_t>> descriptor;
    bool descriptorMissing = false; // a HID report naming a descriptor not read before it
};
RawTrackerMessage
decodeRawTracker(const nlohmann::json& j,
                 const std::map<std::uint32_t, std::shared_ptr<const std::vector<std::uint8_t>>>&
                         descriptors);
// The raw input of accel sample 'sequence'.
std::pair<std::uint32_t, std::shared_ptr<hal::RawAccelInput>>
decodeRawAccel(const nlohmann::json& j);

} // namespace replica::recordings
