// Devices as data: the registry writes exactly the channels format 5 always had (and format 6's),
// and a device kind that is nothing but data (a second accelerometer: new names and channel, the
// accelerometer's sample type and codec) is polled by the loop, recorded, read back, listed and
// replayed; the state stage's kinds reach the estimators typed, a data-only kind does not reach
// them.
#include <filesystem>
#include <set>

#include <pipeline/base/data_dir.h>
#include <platform/appliance.h>
#include <platform/loop/frame_loop.h>
#include <recordings/device_kind.h>
#include <recordings/mcap/reader.h>
#include <recordings/recording.h>
#include <recordings/sample_codec.h>

#include <gtest/gtest.h>

#include "../support/files.h"
#include "../support/headless_gl.h"

namespace replica {
namespace {

using recordings::DeviceKind;
using recordings::DeviceKinds;

// The schemas and channels of the current format as the registry makes them, against those the
// code before the registry wrote into the committed format-5 sample (byte for byte: a viewer and
// 'recover' see the same file), and against the committed format-6 sample, which adds only the
// error probe's channel (id 16).
::testing::AssertionResult sameChannels(const std::string& sample,
                                        const std::set<std::uint16_t>& addedSince)
{
    const std::string file =
            tests::slurp(std::filesystem::path(REPLICA_SOURCE_DIR) / "recordings/samples" / sample);
    if (file.empty()) {
        return ::testing::AssertionFailure() << sample << " is missing";
    }
    const auto scan = recordings::mcap::scan(file);
    if (!scan.damage.empty()) {
        return ::testing::AssertionFailure() << sample << " is damaged";
    }
    const auto& defs = recordings::channelDefinitions();
    if (defs.size() != scan.channels.size() + addedSince.size()) {
        return ::testing::AssertionFailure()
               << sample << ": " << scan.channels.size() << " channels, today " << defs.size();
    }
    for (const auto& d : defs) {
        const auto c = scan.channels.find(d.channel.id);
        if (c == scan.channels.end()) {
            if (addedSince.count(d.channel.id) == 0) {
                return ::testing::AssertionFailure() << sample << ": no " << d.channel.topic;
            }
            continue;
        }
        const auto s = scan.schemas.find(d.schema.id);
        if (!(c->second == d.channel) || s == scan.schemas.end() || !(s->second == d.schema)) {
            return ::testing::AssertionFailure() << sample << ": " << d.channel.topic << " differs";
        }
    }
    return ::testing::AssertionSuccess();
}

TEST(DeviceKinds, WriteTheChannelsAndSchemasOfTheCommittedFormat5Sample)
{
    EXPECT_TRUE(sameChannels("walk-v5.mcap", {16}));
    EXPECT_TRUE(sameChannels("walk-v6.mcap", {}));
    // One registration each: the four devices, in channel order.
    const auto& kinds = recordings::deviceKinds();
    ASSERT_EQ(kinds.size(), 4u);
    EXPECT_EQ(kinds[0], &recordings::spectrometerKind());
    EXPECT_EQ(kinds[3], &recordings::lampSelectorKind());
}

// Scripted samples of the second accelerometer: every 150 ms, with sequence 3 missing (a drop the
// loop must count), gravity a function of the sequence so that values are checkable.
std::vector<hal::AccelSample> secondAccelSamples()
{
    std::vector<hal::AccelSample> out;
    for (std::uint32_t seq = 0; seq < 8; ++seq) {
        if (seq == 3) {
            continue;
        }
        hal::AccelSample s;
        s.sequence = seq;
        s.timestampNs = 50'000'000 + static_cast<std::int64_t>(seq) * 150'000'000;
        s.gravity = {0.25 * seq, -9.81, 0.125};
        out.push_back(s);
    }
    return out;
}

TEST(DeviceKinds, ASecondAccelerometerIsOnlyDataAndIsPolledRecordedReadListedAndReplayed)
{
    // The whole addition: names, a channel, the existing sample type and codec.
    const auto schema = recordings::accelSchema();
    const DeviceKind<hal::AccelSample> secondAccel(
            {"accel2",
             "second accelerometer",
             "samples",
             {17, "/hal/accel2", schema.first, schema.second},
             std::nullopt,
             "accel2_seq",
             "dropped_accel2",
             true},
            recordings::accelCodec());
    DeviceKinds kinds = recordings::deviceKinds();
    kinds.push_back(&secondAccel);

    auto app = platform::buildAppliance(tests::smallSimRun());
    if (!app) {
        GTEST_SKIP() << app.error().message;
    }
    auto sources = platform::makeSimSources(**app);
    ASSERT_TRUE(sources) << sources.error().message;
    const auto scripted = secondAccelSamples();
    sources->set(secondAccel,
                 std::make_unique<hal::ReplaySource<hal::AccelSample>>(
                         hal::DeviceInfo{"accel2 (scripted)", "A2", "", {}}, scripted));

    const auto dir = std::filesystem::temp_directory_path() / "replica-device-kinds-test";
    std::filesystem::create_directories(dir);
    const auto path = dir / "accel2.mcap";
    recordings::SessionInfo session;
    session.softwareVersion = "test";
    session.configJson = (*app)->config.toJson();
    for (const auto& e : sources->entries()) {
        session.devices[e.kind] = e.source->info();
    }
    recordings::WriterOptions options;
    options.kinds = kinds;
    auto writer = recordings::RecordingWriter::create(path, session, options);
    ASSERT_TRUE(writer) << writer.error().message;

    // 10 frames at 10 Hz: ticks 0 .. 900 ms.
    const auto plan = platform::fixedRatePlan((*app)->config.periodNs(), 10);
    std::vector<recordings::FrameRecord> live;
    auto stats = platform::runFrames(
            **app, *sources, plan, platform::Pacing::Fast, writer->get(),
            pipeline::render::Readback::None,
            [&](const recordings::FrameRecord& f, const auto&, const auto&) { live.push_back(f); });
    ASSERT_TRUE(stats) << stats.error().message;
    ASSERT_TRUE((*writer)->close());

    // Polled: each frame consumed the newest scripted sample at or before its tick.
    ASSERT_EQ(live.size(), 10u);
    std::size_t polled = 0;
    for (const auto& f : live) {
        std::optional<std::uint32_t> want;
        for (const auto& s : scripted) {
            if (s.timestampNs <= f.tickNs) {
                want = s.sequence;
            }
        }
        EXPECT_EQ(f.sequence(secondAccel), want) << "frame " << f.frameIndex;
    }
    for (const auto& s : scripted) {
        polled += s.timestampNs <= live.back().tickNs ? 1 : 0;
    }
    EXPECT_EQ(polled, 5u); // t = 50, 200, 350, 650 and 800 ms (the last tick is 900 ms)
    EXPECT_EQ(stats->dropped.at("accel2"), 1u); // sequence 3 never came

    // Recorded and read back with the kinds: the samples bit for bit, the frames' sequences.
    auto rec = recordings::readRecording(path, kinds);
    ASSERT_TRUE(rec) << rec.error().message;
    const auto& back = rec->samples(secondAccel);
    ASSERT_EQ(back.size(), polled);
    for (std::size_t i = 0; i < back.size(); ++i) {
        EXPECT_EQ(back[i].sequence, scripted[i].sequence);
        EXPECT_EQ(back[i].timestampNs, scripted[i].timestampNs);
        EXPECT_EQ(back[i].gravity, scripted[i].gravity);
    }
    EXPECT_EQ(rec->session.device(secondAccel).model, "accel2 (scripted)");
    ASSERT_EQ(rec->frames.size(), live.size());
    for (std::size_t i = 0; i < live.size(); ++i) {
        EXPECT_EQ(rec->frames[i].sequences, live[i].sequences) << i;
    }
    // The built-in devices are unaffected: the first accelerometer has its own samples.
    EXPECT_GT(rec->samples(recordings::accelKind()).size(), 0u);

    // Listed: inspect's channel table has it, with its schema and message count.
    auto report = recordings::inspectRecording(path);
    ASSERT_TRUE(report) << report.error().message;
    bool listed = false;
    for (const auto& c : report->channels) {
        if (c.topic == "/hal/accel2") {
            listed = true;
            EXPECT_EQ(c.id, 17);
            EXPECT_EQ(c.schemaName, "replica.AccelSample");
            EXPECT_EQ(c.messages, polled);
        }
    }
    EXPECT_TRUE(listed);

    // A reader that does not know the kind still reads the file (the channel is skipped).
    auto plain = recordings::readRecording(path);
    ASSERT_TRUE(plain) << plain.error().message;
    EXPECT_EQ(plain->frames.size(), live.size());
    EXPECT_EQ(plain->count(secondAccel), 0u);

    // Replayed: the replay sources include it and every recorded sample is found again.
    auto replayed = platform::makeReplaySources(*rec, kinds);
    ASSERT_NE(replayed.get(secondAccel), nullptr);
    std::vector<recordings::FrameRecord> again;
    auto replayStats =
            platform::runFrames(**app, replayed, platform::replayPlan(rec->frames),
                                platform::Pacing::Fast, nullptr, pipeline::render::Readback::None,
                                [&](const recordings::FrameRecord& f, const auto&, const auto&) {
                                    again.push_back(f);
                                });
    ASSERT_TRUE(replayStats) << replayStats.error().message;
    EXPECT_EQ(replayStats->replayMismatches, 0u);
    ASSERT_EQ(again.size(), live.size());
    for (std::size_t i = 0; i < live.size(); ++i) {
        EXPECT_EQ(again[i].sequences, live[i].sequences) << i;
    }
    std::filesystem::remove_all(dir);
}

// The state stage's kinds are typed: the loop's slots hand the estimators one typed sample per
// kind of recordings::StateKinds (frame_loop.cpp checks at compile time that
// state::SceneEstimator::update takes exactly those). A kind outside them is data only: it has a
// slot (polled, recorded) but no estimator gets its samples, even of the same sample type.
TEST(DeviceKinds, TheEstimatorsGetTypedSamplesOfTheStateKindsAndADataKindIsPolledOnly)
{
    const auto schema = recordings::accelSchema();
    const DeviceKind<hal::AccelSample> secondAccel(
            {"accel2",
             "second accelerometer",
             "samples",
             {17, "/hal/accel2", schema.first, schema.second},
             std::nullopt,
             "accel2_seq",
             "dropped_accel2",
             true},
            recordings::accelCodec());
    hal::AccelSample first;
    first.sequence = 7;
    first.timestampNs = 10;
    first.gravity = {0.0, -9.81, 0.0};
    hal::AccelSample second = first;
    second.sequence = 9;
    second.gravity = {1.0, -9.0, 0.5};
    recordings::Sources sources;
    sources.set(secondAccel, std::make_unique<hal::ReplaySource<hal::AccelSample>>(
                                     hal::DeviceInfo{"accel2", "A2", "", {}},
                                     std::vector<hal::AccelSample>{second}));
    sources.set(recordings::accelKind(), std::make_unique<hal::ReplaySource<hal::AccelSample>>(
                                                 hal::DeviceInfo{"accel", "A1", "", {}},
                                                 std::vector<hal::AccelSample>{first}));
    recordings::DeviceSink* tee = nullptr;
    const recordings::StateSlots slots(recordings::stateKinds(), sources, &tee);
    ASSERT_EQ(slots.all().size(), 2u);
    EXPECT_EQ(&slots.all()[0]->kind(), &recordings::accelKind()); // channel order: 4, then 17
    EXPECT_EQ(&slots.all()[1]->kind(), &secondAccel);
    std::uint64_t mismatches = 0;
    for (const auto& slot : slots.all()) {
        slot->poll(100);
        slot->choose(std::nullopt, false, mismatches);
    }
    EXPECT_EQ(slots.all()[1]->chosenSequence(), 9u); // the data kind's slot did choose its sample
    const auto [spectrum, pose, accel, lamp] = slots.chosen();
    EXPECT_EQ(spectrum, nullptr);
    EXPECT_EQ(pose, nullptr);
    EXPECT_EQ(lamp, nullptr);
    ASSERT_NE(accel, nullptr);
    EXPECT_EQ(accel->sequence, 7u); // the registered accelerometer's, never the second one's
    EXPECT_EQ(accel->gravity, first.gravity);
    // The type-erased registry is the typed one, in its order.
    const auto& kinds = recordings::deviceKinds();
    ASSERT_EQ(kinds.size(), std::tuple_size_v<recordings::StateKinds>);
    EXPECT_EQ(kinds[0], std::get<0>(recordings::stateKinds()));
    EXPECT_EQ(kinds[2], std::get<2>(recordings::stateKinds()));
}

} // namespace
} // namespace replica
