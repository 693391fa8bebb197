// Devices as data: one description per device kind (its sample type, names, channel, schema and
// codec), and the generic pieces built from it that the loop, the recorder, the reader, replay and
// inspect iterate over. deviceKinds() is the registry; adding a device kind is its HAL folder, its
// codec, and one line there (recordings/README.md, "Device kinds").
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include <hal/replay/replay_source.h>
#include <hal/sample_latch.h>
#include <hal/sources.h>

namespace replica::recordings {

// One channel of a recording: fixed id, topic, and its JSON Schema.
struct ChannelSpec {
    std::uint16_t id = 0;
    std::string topic;
    std::string schemaName;
    std::string schemaText;
};

// Everything about a device kind that is not code.
struct DeviceNames {
    std::string name;        // key in the session, the run's summary and 'inspect --json'
    std::string displayName; // for people: "accelerometer"
    std::string samplesNoun; // what its samples are called in log lines: "spectra", "poses"
    ChannelSpec channel;     // its samples
    std::optional<ChannelSpec> rawChannel; // format 5: what the device gave before processing
    std::string frameKey;                  // /replica/frame: the sequence consumed, "accel_seq"
    std::string droppedKey;                // /replica/recorder: samples dropped, "dropped_accel"
    bool optional = false; // a session may have none: recordings before it, a booth without one
    // 'replica run --<name, '_' as '-'>' (and the site file's [sources] <name>): where a run takes
    // the kind's samples from. 'sources' are the option's values: "sim..." simulated, "replay",
    // "none" (optional kinds), any other a live driver; 'liveSource' is what --hal live means
    // for the kind (an optional kind has none unless asked); 'sourceHelp' the option's help.
    std::vector<std::string> sources{};
    std::string liveSource{};
    std::string sourceHelp{};
};

// Where the writer thread puts a device's encoded messages (in order), and how it reports a raw
// input it could not encode.
struct DeviceEmitter {
    std::function<void(std::uint16_t channel, std::int64_t tNs, std::string payload)> message;
    std::function<void()> rejectRaw;
};

class DeviceKindBase;

// What a sample type's raw-channel codec (format 5) keeps: the writer from one sample to the next,
// the reader from the first raw message until every raw input is attached to its sample. A type
// without a raw channel keeps nothing; a type with one specializes this (below).
template <typename Sample>
struct RawCodecState {
    struct Writer {
    };
    struct Reader {
    };
};

// The head tracker's: the HID descriptor written last and its id (a descriptor is written once
// per opening of the device, before its first report); the reader's descriptors by id and raw
// inputs by pose sequence.
template <>
struct RawCodecState<hal::PoseSample> {
    struct Writer {
        std::shared_ptr<const std::vector<std::uint8_t>> lastDescriptor;
        std::uint32_t descriptorId = 0;
    };
    struct Reader {
        std::map<std::uint32_t, std::shared_ptr<const std::vector<std::uint8_t>>> descriptors;
        std::map<std::uint32_t, std::shared_ptr<const hal::RawTrackerInput>> raw;
    };
};

// The accelerometer's: the writer keeps nothing; the reader its raw inputs by sample sequence.
template <>
struct RawCodecState<hal::AccelSample> {
    struct Writer {
    };
    struct Reader {
        std::map<std::uint32_t, std::shared_ptr<const hal::RawAccelInput>> raw;
    };
};

// The sample types the device kinds have, and what is held of each as a closed set (variants):
// one sample (the recorder's queue), a recording's samples of a kind (the reader), the raw
// codec's state (writer and reader). A kind of another type does not compile (DeviceKind's
// static_assert): its type joins SampleTypes.
template <typename... Samples>
struct SampleTypeList {
    using Sample = std::variant<Samples...>;
    using SampleVectors = std::variant<std::vector<Samples>...>;
    using WriterState = std::variant<typename RawCodecState<Samples>::Writer...>;
    using ReaderState = std::variant<typename RawCodecState<Samples>::Reader...>;
};
using SampleTypes =
        SampleTypeList<hal::SpectrumSample, hal::PoseSample, hal::AccelSample, hal::LampSample>;
using AnySample = SampleTypes::Sample;
using AnySamples = SampleTypes::SampleVectors;
using AnyWriterState = SampleTypes::WriterState;
using AnyReaderState = SampleTypes::ReaderState;

// What a sample of any kind is written to: the recording writer, and in tests anything else.
class DeviceSink
{
public:
    virtual ~DeviceSink() = default;
    virtual void writeDevice(const DeviceKindBase& kind, AnySample sample) = 0;
};

// The loop's per-device slot: polls the source, keeps the latest samples (hal::SampleLatch),
// chooses the one a frame uses (live: the latest; replay: the recorded one).
class DeviceSlot
{
public:
    virtual ~DeviceSlot() = default;
    virtual const DeviceKindBase& kind() const = 0;
    virtual hal::AnySource& source() = 0;
    // Polls up to untilNs; returns how many samples the sequence numbers say were lost.
    virtual std::uint64_t poll(std::int64_t untilNs) = 0;
    // Live (!replaying): the latest sample. Replay: the sample 'wanted' (none: the recorded frame
    // had none yet), else the latest, counting a mismatch.
    virtual void choose(const std::optional<std::uint32_t>& wanted,
                        bool replaying,
                        std::uint64_t& mismatches) = 0;
    virtual std::optional<std::uint32_t> chosenSequence() const = 0;
    // A new recording file starts with what the scene holds now.
    virtual void writeLatest(DeviceSink& sink) const = 0;
};

// The one description of a device kind, its sample type erased: what the recorder, reader,
// replay and inspect need. A sample to write travels as an AnySample holding the kind's Sample;
// a recording's samples of a kind (the reader's side) as an AnySamples holding
// std::vector<Sample>; the raw codec's state as an AnyWriterState / AnyReaderState holding
// RawCodecState<Sample>'s. Each kind makes its own (emptySamples, writerState, readerState), so
// the alternative a kind is handed is always its own.
class DeviceKindBase
{
public:
    explicit DeviceKindBase(DeviceNames names) : names_(std::move(names)) {}
    virtual ~DeviceKindBase() = default;
    DeviceKindBase(const DeviceKindBase&) = delete;
    DeviceKindBase& operator=(const DeviceKindBase&) = delete;

    const DeviceNames& names() const { return names_; }
    const std::string& name() const { return names_.name; }
    virtual const std::type_info& sampleType() const = 0;

    // Writer thread: the sample's messages through 'emit' (its own channel, then any raw input);
    // false when the sample cannot be written (a NaN or infinite value). 'state' is the kind's
    // own, kept by the writer from sample to sample (e.g. the HID descriptor written last).
    virtual AnyWriterState writerState() const = 0;
    virtual bool
    encode(const AnySample& sample, AnyWriterState& state, const DeviceEmitter& emit) const = 0;

    // Reader. decode throws a std::exception (nlohmann::json's on a missing or mistyped field,
    // std::out_of_range on an integer that does not fit: codec_json.h's integerField).
    virtual AnySamples emptySamples() const = 0;
    virtual std::size_t count(const AnySamples& samples) const = 0;
    virtual void decode(const nlohmann::json& j, AnySamples& samples) const = 0;
    virtual AnyReaderState readerState() const = 0;
    // A raw-channel message; returns false when it names what the file does not hold (unusable).
    virtual bool decodeRaw(const nlohmann::json& j, AnyReaderState& state) const = 0;
    // Gives each sample its raw input; returns how many raw inputs found no sample.
    virtual std::uint64_t attachRaw(AnySamples& samples, AnyReaderState& state) const = 0;
    // Drops the raw inputs read so far and keeps what later raw messages refer to (the HID
    // descriptors): recover checks a file's messages one at a time and holds none of them.
    virtual void forgetRawInputs(AnyReaderState& state) const = 0;
    // How many samples carry a raw input (inspect).
    virtual std::uint64_t countWithRaw(const AnySamples& samples) const = 0;
    // Each sample's time, in the recording's order.
    virtual std::vector<std::int64_t> times(const AnySamples& samples) const = 0;
    // Sample i as its channel's message (JSON); nullopt when it cannot be written.
    virtual std::optional<std::string> encodeAt(const AnySamples& samples, std::size_t i) const = 0;

    // Replay: a source that returns exactly these samples.
    virtual std::unique_ptr<hal::AnySource> replaySource(const hal::DeviceInfo& recorded,
                                                         const AnySamples& samples) const = 0;
    // The loop: a slot polling 'source' (which must deliver this kind's Sample); with 'tee',
    // every polled sample is also written there (recording as a decorator on the source).
    virtual std::unique_ptr<DeviceSlot> makeSlot(hal::AnySource& source,
                                                 DeviceSink* const* tee) const = 0;

private:
    DeviceNames names_;
};

// The codec of a sample type: plain functions, so that a second device of an existing type is
// nothing but data (a DeviceKind with other names and the same codec).
template <typename Sample>
struct SampleCodec {
    std::function<std::optional<std::string>(const Sample&)> encode; // nullopt: not finite
    std::function<Sample(const nlohmann::json&)> decode;
    // Format 5, optional: the raw input beside the sample, on DeviceNames::rawChannel.
    using WriterState = typename RawCodecState<Sample>::Writer;
    using ReaderState = typename RawCodecState<Sample>::Reader;
    std::function<void(const Sample&, std::uint16_t channel, WriterState&, const DeviceEmitter&)>
            encodeRaw;
    std::function<bool(const nlohmann::json&, ReaderState&)> decodeRaw;
    std::function<std::uint64_t(std::vector<Sample>&, ReaderState&)> attachRaw;
    std::function<bool(const Sample&)> hasRaw;
};

// Records a source: every sample polled from it is also written to *tee (when set). Record = tee
// a source into a sink; replay = a source (hal::ReplaySource).
template <typename Sample>
class RecordingSource final : public hal::Source<Sample>
{
public:
    RecordingSource(hal::Source<Sample>& inner, const DeviceKindBase& kind, DeviceSink* const* tee)
        : inner_(inner), kind_(kind), tee_(tee)
    {}
    const hal::DeviceInfo& info() const override { return inner_.info(); }
    hal::LinkState state() const override { return inner_.state(); }
    void poll(std::int64_t untilNs, std::vector<Sample>& out) override
    {
        const std::size_t first = out.size();
        inner_.poll(untilNs, out);
        if (tee_ != nullptr && *tee_ != nullptr) {
            for (std::size_t i = first; i < out.size(); ++i) {
                (*tee_)->writeDevice(kind_, AnySample(out[i]));
            }
        }
    }

private:
    hal::Source<Sample>& inner_;
    const DeviceKindBase& kind_;
    DeviceSink* const* tee_;
};

template <typename Sample>
class TypedDeviceSlot final : public DeviceSlot
{
public:
    TypedDeviceSlot(const DeviceKindBase& kind, hal::Source<Sample>& source, DeviceSink* const* tee)
        : kind_(kind), source_(source), polled_(source, kind, tee)
    {}
    const DeviceKindBase& kind() const override { return kind_; }
    hal::AnySource& source() override { return source_; }
    std::uint64_t poll(std::int64_t untilNs) override
    {
        fresh_.clear();
        polled_.poll(untilNs, fresh_);
        return latch_.push(fresh_);
    }
    void choose(const std::optional<std::uint32_t>& wanted,
                bool replaying,
                std::uint64_t& mismatches) override
    {
        if (!replaying) {
            chosen_ = latch_.latest();
        } else if (!wanted) {
            chosen_ = nullptr; // the original frame had no sample of this device yet
        } else if (const Sample* s = latch_.find(*wanted)) {
            chosen_ = s;
        } else {
            ++mismatches;
            chosen_ = latch_.latest();
        }
    }
    std::optional<std::uint32_t> chosenSequence() const override
    {
        return chosen_ != nullptr ? std::optional<std::uint32_t>(chosen_->sequence) : std::nullopt;
    }
    void writeLatest(DeviceSink& sink) const override
    {
        if (const Sample* s = latch_.latest()) {
            sink.writeDevice(kind_, AnySample(*s));
        }
    }
    const Sample* chosen() const { return chosen_; }

private:
    const DeviceKindBase& kind_;
    hal::Source<Sample>& source_;
    RecordingSource<Sample> polled_;
    hal::SampleLatch<Sample> latch_;
    std::vector<Sample> fresh_;
    const Sample* chosen_ = nullptr;
};

// A device kind of one sample type: names plus that type's codec.
template <typename Sample>
class DeviceKind final : public DeviceKindBase
{
    static_assert(std::is_constructible_v<AnySample, Sample>,
                  "a device kind's sample type must be one of AnySample's");

    using WriterState = typename SampleCodec<Sample>::WriterState;
    using ReaderState = typename SampleCodec<Sample>::ReaderState;

public:
    DeviceKind(DeviceNames names, SampleCodec<Sample> codec)
        : DeviceKindBase(std::move(names)), codec_(std::move(codec))
    {}
    const std::type_info& sampleType() const override { return typeid(Sample); }

    AnyWriterState writerState() const override { return WriterState{}; }
    bool
    encode(const AnySample& sample, AnyWriterState& state, const DeviceEmitter& emit) const override
    {
        const auto& s = std::get<Sample>(sample);
        auto payload = codec_.encode(s);
        if (!payload) {
            return false;
        }
        emit.message(names().channel.id, s.timestampNs, std::move(*payload));
        if (codec_.encodeRaw && names().rawChannel) {
            codec_.encodeRaw(s, names().rawChannel->id, std::get<WriterState>(state), emit);
        }
        return true;
    }
    AnySamples emptySamples() const override { return std::vector<Sample>{}; }
    std::size_t count(const AnySamples& samples) const override { return of(samples).size(); }
    void decode(const nlohmann::json& j, AnySamples& samples) const override
    {
        of(samples).push_back(codec_.decode(j));
    }
    AnyReaderState readerState() const override { return ReaderState{}; }
    bool decodeRaw(const nlohmann::json& j, AnyReaderState& state) const override
    {
        return codec_.decodeRaw ? codec_.decodeRaw(j, std::get<ReaderState>(state)) : false;
    }
    std::uint64_t attachRaw(AnySamples& samples, AnyReaderState& state) const override
    {
        return codec_.attachRaw ? codec_.attachRaw(of(samples), std::get<ReaderState>(state)) : 0;
    }
    void forgetRawInputs(AnyReaderState& state) const override
    {
        auto& st = std::get<ReaderState>(state);
        if constexpr (requires { st.raw.clear(); }) {
            st.raw.clear();
        }
    }
    std::uint64_t countWithRaw(const AnySamples& samples) const override
    {
        std::uint64_t n = 0;
        if (codec_.hasRaw) {
            for (const auto& s : of(samples)) {
                n += codec_.hasRaw(s) ? 1 : 0;
            }
        }
        return n;
    }
    std::vector<std::int64_t> times(const AnySamples& samples) const override
    {
        std::vector<std::int64_t> t;
        for (const auto& s : of(samples)) {
            t.push_back(s.timestampNs);
        }
        return t;
    }
    std::optional<std::string> encodeAt(const AnySamples& samples, std::size_t i) const override
    {
        return codec_.encode(of(samples).at(i));
    }
    std::unique_ptr<hal::AnySource> replaySource(const hal::DeviceInfo& recorded,
                                                 const AnySamples& samples) const override
    {
        return std::make_unique<hal::ReplaySource<Sample>>(recorded, of(samples));
    }
    std::unique_ptr<DeviceSlot> makeSlot(hal::AnySource& source,
                                         DeviceSink* const* tee) const override
    {
        return std::make_unique<TypedDeviceSlot<Sample>>(
                *this, dynamic_cast<hal::Source<Sample>&>(source), tee);
    }

    // This kind's alternative of samples it made (emptySamples).
    static std::vector<Sample>& of(AnySamples& samples)
    {
        return std::get<std::vector<Sample>>(samples);
    }
    static const std::vector<Sample>& of(const AnySamples& samples)
    {
        return std::get<std::vector<Sample>>(samples);
    }

private:
    SampleCodec<Sample> codec_;
};

// The registry, typed: the device kinds the state stage consumes, one DeviceKind each, as a
// tuple in channel-id order. The loop makes a typed slot for each (DeviceSlots) and hands their
// chosen samples to the estimators as typed pointers, in this order
// (state::SceneEstimator::update; platform/loop/frame_loop.cpp checks at compile time that it
// takes exactly these). A kind outside this tuple is data only: polled, recorded, read, listed
// and replayed, and consumed by nothing.
template <typename... Samples>
using KindTuple = std::tuple<const DeviceKind<Samples>*...>;
using StateKinds =
        KindTuple<hal::SpectrumSample, hal::PoseSample, hal::AccelSample, hal::LampSample>;
const StateKinds& stateKinds();

// Every device kind this build knows (the typed ones, as DeviceKindBase), in channel-id order.
// The order is the order the loop polls and records them in.
using DeviceKinds = std::vector<const DeviceKindBase*>;
const DeviceKinds& deviceKinds();

// The registered kinds by name (the four of format 5).
const DeviceKind<hal::SpectrumSample>& spectrometerKind();
const DeviceKind<hal::PoseSample>& trackerKind();
const DeviceKind<hal::AccelSample>& accelKind();
const DeviceKind<hal::LampSample>& lampSelectorKind();

// The first registered kind of this sample type (what RecordingWriter::write(sample) uses); null
// when none.
const DeviceKindBase* kindOfType(const DeviceKinds& kinds, const std::type_info& type);

// The sources of a run, one per device kind present, kept in channel-id order (the order they
// are polled and recorded in).
class Sources
{
public:
    void set(const DeviceKindBase& kind, std::unique_ptr<hal::AnySource> source);
    template <typename Sample>
    void set(const DeviceKind<Sample>& kind,
             std::type_identity_t<std::unique_ptr<hal::Source<Sample>>> source)
    {
        set(static_cast<const DeviceKindBase&>(kind),
            std::unique_ptr<hal::AnySource>(std::move(source)));
    }
    // Null when the run has no such device.
    hal::AnySource* get(const DeviceKindBase& kind) const;
    template <typename Sample>
    hal::Source<Sample>* get(const DeviceKind<Sample>& kind) const
    {
        return static_cast<hal::Source<Sample>*>(get(static_cast<const DeviceKindBase&>(kind)));
    }
    // Takes the source out (to wrap it, e.g. fault injection); null when none.
    std::unique_ptr<hal::AnySource> take(const DeviceKindBase& kind)
    {
        for (auto& e : entries_) {
            if (e.kind == &kind) {
                return std::move(e.source);
            }
        }
        return nullptr;
    }
    template <typename Sample>
    std::unique_ptr<hal::Source<Sample>> take(const DeviceKind<Sample>& kind)
    {
        for (auto& e : entries_) {
            if (e.kind == &kind && e.source) {
                return std::unique_ptr<hal::Source<Sample>>(
                        static_cast<hal::Source<Sample>*>(e.source.release()));
            }
        }
        return nullptr;
    }
    struct Entry {
        const DeviceKindBase* kind = nullptr;
        std::unique_ptr<hal::AnySource> source; // null: none
    };
    std::vector<Entry>& entries() { return entries_; }
    const std::vector<Entry>& entries() const { return entries_; }

private:
    std::vector<Entry> entries_;
};

// A run's slots, one per source it has, in the sources' (channel-id) order: the loop polls,
// chooses and records through all(); the slot of each kind of 'kinds' is also held typed, and
// chosen() gives their chosen samples as typed pointers (null: the run has no such device, or
// none yet). A source of a kind outside 'kinds' gets a slot of its own type (data only).
template <typename... Samples>
class DeviceSlots
{
public:
    DeviceSlots(const KindTuple<Samples...>& kinds, Sources& sources, DeviceSink* const* tee)
    {
        for (auto& e : sources.entries()) {
            if (!e.source) {
                continue;
            }
            bool typed = false;
            adoptTyped(kinds, e, tee, typed, std::index_sequence_for<Samples...>{});
            if (!typed) {
                all_.push_back(e.kind->makeSlot(*e.source, tee));
            }
        }
    }
    const std::vector<std::unique_ptr<DeviceSlot>>& all() const { return all_; }
    std::tuple<const Samples*...> chosen() const
    {
        return std::apply(
                [](const auto*... slot) {
                    return std::tuple<const Samples*...>{
                            (slot != nullptr ? slot->chosen() : nullptr)...};
                },
                typed_);
    }

private:
    template <std::size_t... I>
    void adoptTyped(const KindTuple<Samples...>& kinds,
                    Sources::Entry& e,
                    DeviceSink* const* tee,
                    bool& typed,
                    std::index_sequence<I...>)
    {
        (adopt<I>(*std::get<I>(kinds), e, tee, typed), ...);
    }
    template <std::size_t I, typename Sample>
    void
    adopt(const DeviceKind<Sample>& kind, Sources::Entry& e, DeviceSink* const* tee, bool& typed)
    {
        if (typed || e.kind != &kind) {
            return;
        }
        // Sources::set keeps a kind's source of its own sample type (hal::Source<Sample>).
        auto slot = std::make_unique<TypedDeviceSlot<Sample>>(
                kind, static_cast<hal::Source<Sample>&>(*e.source), tee);
        std::get<I>(typed_) = slot.get();
        all_.push_back(std::move(slot));
        typed = true;
    }

    std::vector<std::unique_ptr<DeviceSlot>> all_;
    std::tuple<TypedDeviceSlot<Samples>*...> typed_{};
};

// The slots of the typed registry's kinds (StateKinds): what the loop holds.
template <typename Kinds>
struct SlotsFor;
template <typename... Samples>
struct SlotsFor<KindTuple<Samples...>> {
    using type = DeviceSlots<Samples...>;
};
using StateSlots = SlotsFor<StateKinds>::type;

} // namespace replica::recordings
