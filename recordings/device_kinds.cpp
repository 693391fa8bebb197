// The registry of device kinds: one description each (names, channel, schema, codec). A new kind
// is a function below and one line in deviceKinds().
#include <algorithm>

#include <recordings/device_kind.h>
#include <recordings/sample_codec.h>

namespace replica::recordings {
namespace {

ChannelSpec
channel(ChannelId id, std::string_view topic, const std::pair<std::string, std::string>& schema)
{
    return {static_cast<std::uint16_t>(id), std::string(topic), schema.first, schema.second};
}

} // namespace

const DeviceKind<hal::SpectrumSample>& spectrometerKind()
{
    static const DeviceKind<hal::SpectrumSample> kind(
            {"spectrometer",
             "spectrometer",
             "spectra",
             channel(ChannelId::Spectrometer, kSpectrometerTopic, spectrumSchema()),
             std::nullopt,
             "spectrum_seq",
             "dropped_spectra",
             false,
             {"live", "sim", "replay"},
             "live",
             "the spectrometer's source: live (USB2000+), sim or replay (default: --hal)"},
            spectrumCodec());
    return kind;
}

const DeviceKind<hal::PoseSample>& trackerKind()
{
    static const DeviceKind<hal::PoseSample> kind(
            {"tracker",
             "tracker",
             "poses",
             channel(ChannelId::Tracker, kTrackerTopic, poseSchema()),
             channel(ChannelId::RawTracker, kRawTrackerTopic, rawTrackerSchema()),
             "pose_seq",
             "dropped_poses",
             false,
             {"opentrack", "hid", "sim", "replay"},
             "opentrack",
             "the head tracker's source: opentrack (UDP), hid (a USB HID eye/head tracker, "
             "usage page 0x12), sim or replay (default: opentrack with --hal live, else sim)"},
            poseCodec());
    return kind;
}

const DeviceKind<hal::AccelSample>& accelKind()
{
    static const DeviceKind<hal::AccelSample> kind(
            {"accel",
             "accelerometer",
             "samples",
             channel(ChannelId::Accel, kAccelTopic, accelSchema()),
             channel(ChannelId::RawAccel, kRawAccelTopic, rawAccelSchema()),
             "accel_seq",
             "dropped_accel",
             false,
             {"live", "sim", "replay"},
             "live",
             "the accelerometer's source: live (IIO), sim or replay (default: --hal)"},
            accelCodec());
    return kind;
}

const DeviceKind<hal::LampSample>& lampSelectorKind()
{
    static const DeviceKind<hal::LampSample> kind(
            {"lamp_selector",
             "lamp selector",
             "samples",
             channel(ChannelId::LampSelector, kLampSelectorTopic, lampSchema()),
             std::nullopt,
             "lamp_seq",
             "dropped_lamp",
             true,
             {"none", "gpio", "sim", "sim-miswired", "replay"},
             "gpio",
             "the booth's lamp switch: none, gpio (the live switch on --lamp-gpio; the "
             "default when that is given), sim (follows the simulated lamps, with contact "
             "bounce), sim-miswired (its lines for lamps 1 and 2 swapped) or replay"},
            lampCodec());
    return kind;
}

const StateKinds& stateKinds()
{
    static const StateKinds kinds{
            &spectrometerKind(),
            &trackerKind(),
            &accelKind(),
            &lampSelectorKind(),
    };
    return kinds;
}

const DeviceKinds& deviceKinds()
{
    static const DeviceKinds kinds =
            std::apply([](const auto*... kind) { return DeviceKinds{kind...}; }, stateKinds());
    return kinds;
}

const DeviceKindBase* kindOfType(const DeviceKinds& kinds, const std::type_info& type)
{
    for (const auto* k : kinds) {
        if (k->sampleType() == type) {
            return k;
        }
    }
    return nullptr;
}

void Sources::set(const DeviceKindBase& kind, std::unique_ptr<hal::AnySource> source)
{
    for (auto& e : entries_) {
        if (e.kind == &kind) {
            e.source = std::move(source);
            return;
        }
    }
    entries_.push_back({&kind, std::move(source)});
    // Channel-id order: the order the loop polls and the recorder writes them in.
    std::stable_sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) {
        return a.kind->names().channel.id < b.kind->names().channel.id;
    });
}

hal::AnySource* Sources::get(const DeviceKindBase& kind) const
{
    for (const auto& e : entries_) {
        if (e.kind == &kind) {
            return e.source.get();
        }
    }
    return nullptr;
}

} // namespace replica::recordings
