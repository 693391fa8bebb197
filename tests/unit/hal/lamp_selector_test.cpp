// The lamp selector: one-hot decoding, debouncing of contact bounce, the driver against scripted
// GPIO lines (initial state, bouncy turns, a removed chip), the threaded live source's fallback
// when the chip cannot be opened, the real libgpiod adapter's error for a missing chip, and the
// simulated switch (agrees with the scenario's light, bounces, and is debounced like the live one).
#include <chrono>
#include <thread>

#include <hal/lamp/gpio_lamp_source.h>
#include <hal/lamp/lamp_debouncer.h>
#include <hal/lamp/libgpiod_lines.h>
#include <hal/sim/scenario.h>
#include <hal/sim/sim_devices.h>

#include <gtest/gtest.h>

#include "fake_gpio_lines.h"

namespace replica::tests {
namespace {

using hal::lamp::decodeOneHot;
using hal::lamp::LampDebouncer;
constexpr std::int64_t kMs = 1'000'000;

TEST(LampDecode, OneLineIsALampNoneIsOffSeveralAreInvalid)
{
    EXPECT_EQ(decodeOneHot(0b000), hal::kLampOff);
    EXPECT_EQ(decodeOneHot(0b001), 0);
    EXPECT_EQ(decodeOneHot(0b010), 1);
    EXPECT_EQ(decodeOneHot(0b100), 2);
    EXPECT_EQ(decodeOneHot(0b110), hal::kLampInvalid);
    EXPECT_EQ(decodeOneHot(0x80000000u), 31);
}

TEST(LampDebounce, BouncesSettleOnceAtTheLastEdgePlusTheDebounceTime)
{
    LampDebouncer d(30 * kMs);
    const auto first = d.start(0b001, 0);
    EXPECT_EQ(first.levels, 0b001u);
    // Break, chatter of the old contact, make with chatter on the new one.
    const std::vector<std::pair<std::int64_t, std::uint32_t>> edges = {
            {1000 * kMs, 0b000},           {1000 * kMs + 300'000, 0b001},
            {1001 * kMs, 0b000},           {1002 * kMs, 0b010},
            {1002 * kMs + 500'000, 0b000}, {1003 * kMs, 0b010},
            {1004 * kMs, 0b000},           {1005 * kMs, 0b010}};
    for (const auto& [t, levels] : edges) {
        EXPECT_FALSE(d.settle(t)) << "settled in the middle of the bounce at " << t;
        d.observe(levels, t);
    }
    EXPECT_EQ(d.dueNs(), 1035 * kMs);
    EXPECT_FALSE(d.settle(1035 * kMs - 1));
    const auto s = d.settle(1035 * kMs);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->levels, 0b010u);
    EXPECT_EQ(s->settledNs, 1035 * kMs);
    EXPECT_FALSE(d.settle(2000 * kMs)) << "a settled position is reported once";
    EXPECT_FALSE(d.dueNs());
}

TEST(LampDebounce, AGlitchShorterThanTheDebounceTimeIsIgnored)
{
    LampDebouncer d(30 * kMs);
    d.start(0b100, 0);
    d.observe(0b000, 500 * kMs); // a knock on the switch: the contact opens for 5 ms
    d.observe(0b100, 505 * kMs);
    EXPECT_FALSE(d.dueNs());
    EXPECT_FALSE(d.settle(600 * kMs));
}

TEST(LampGpioSpec, ParsesChipAndOffsetsAndExplainsBadOnes)
{
    auto s = hal::lamp::parseGpioLineSpec("gpiochip0:17,27,22");
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s->chip, "gpiochip0");
    EXPECT_EQ(s->offsets, (std::vector<unsigned>{17, 27, 22}));
    EXPECT_EQ(hal::lamp::toString(*s), "gpiochip0:17,27,22");
    auto path = hal::lamp::parseGpioLineSpec("/dev/gpiochip1:3");
    ASSERT_TRUE(path);
    EXPECT_EQ(path->chip, "/dev/gpiochip1");
    for (const char* bad : {"gpiochip0", ":1,2", "gpiochip0:", "gpiochip0:1,,2", "gpiochip0:1,x",
                            "gpiochip0:-1", "gpiochip0:1,2,1", "gpiochip0:1,2,", "c:99999"}) {
        auto e = hal::lamp::parseGpioLineSpec(bad);
        ASSERT_FALSE(e) << bad;
        EXPECT_NE(e.error().message.find("--lamp-gpio '" + std::string(bad) + "'"),
                  std::string::npos)
                << e.error().message;
        EXPECT_NE(e.error().message.find("CHIP:OFFSET"), std::string::npos);
    }
}

TEST(LampSelectorReader, ReadsThePositionAtOpenThenDebouncesABouncyTurn)
{
    hal::VirtualClock clock;
    clock.set(5 * kMs);
    const std::vector<FakeGpioLines::Change> script = {
            {2000 * kMs, 0b000},           {2000 * kMs + 400'000, 0b001},
            {2001 * kMs, 0b000},           {2003 * kMs, 0b100},
            {2003 * kMs + 700'000, 0b000}, {2004 * kMs, 0b100},
            {2004 * kMs + 200'000, 0b000}, {2006 * kMs, 0b100}};
    auto owned = std::make_unique<FakeGpioLines>(clock, 0b001, script);
    FakeGpioLines* lines = owned.get();
    hal::lamp::LampSelectorReader reader(std::move(owned), 3, clock, 30 * kMs);
    auto first = reader.start(0);
    ASSERT_TRUE(first) << first.error().message;
    EXPECT_EQ(first->lamp, 0);
    EXPECT_EQ(first->lineLevels, 0b001u);
    EXPECT_EQ(first->lineCount, 3u);
    EXPECT_EQ(first->timestampNs, 5 * kMs);

    std::vector<hal::LampSample> got;
    while (clock.nowNs() < 3000 * kMs) {
        auto s = reader.step(50 * kMs, static_cast<std::uint32_t>(got.size() + 1));
        ASSERT_TRUE(s) << s.error().message;
        if (*s) {
            got.push_back(**s);
        }
    }
    ASSERT_EQ(got.size(), 1u) << "the bounce must not show as extra positions";
    EXPECT_EQ(got[0].lamp, 2);
    EXPECT_EQ(got[0].lineLevels, 0b100u);
    EXPECT_EQ(got[0].sequence, 1u);
    EXPECT_EQ(got[0].timestampNs, 2036 * kMs); // last edge at 2006 ms + 30 ms
    // While a change settles the driver waits only until it is due, never the full 50 ms.
    EXPECT_LE(lines->maxTimeoutNs(), 50 * kMs);
}

TEST(LampSelectorReader, ARemovedChipIsAnErrorNamingIt)
{
    hal::VirtualClock clock;
    auto owned =
            std::make_unique<FakeGpioLines>(clock, 0b010, std::vector<FakeGpioLines::Change>{});
    owned->failFrom(700 * kMs, "fakechip: waiting for edges failed (No such device); was the "
                               "GPIO chip removed?");
    hal::lamp::LampSelectorReader reader(std::move(owned), 3, clock);
    ASSERT_TRUE(reader.start(0));
    for (int i = 0; i < 100; ++i) {
        auto s = reader.step(50 * kMs, 1);
        if (!s) {
            EXPECT_NE(s.error().message.find("fakechip"), std::string::npos);
            EXPECT_GE(clock.nowNs(), 700 * kMs);
            return;
        }
    }
    FAIL() << "the removed chip was never reported";
}

// Waits (up to a generous bound) until the source has queued 'n' samples.
std::vector<hal::LampSample> pollUntil(hal::LampSelectorSource& src, std::size_t n)
{
    std::vector<hal::LampSample> got;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (got.size() < n && std::chrono::steady_clock::now() < deadline) {
        src.poll(INT64_MAX, got);
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return got;
}

TEST(GpioLampSource, AChipThatCannotBeOpenedMeansLostAndALostSampleThenItRecovers)
{
    hal::SteadyClock steady;
    hal::VirtualClock fakeTime; // the fake's own time: it only orders its script
    int opens = 0;
    hal::lamp::GpioOpener opener = [&](const hal::lamp::GpioLineSpec& spec)
            -> Expected<std::unique_ptr<hal::lamp::GpioLines>> {
        if (++opens == 1) {
            return makeError(ErrorCode::Io, "GPIO chip '" + spec.chip +
                                                    "': permission denied; install "
                                                    "deploy/udev/60-replica.rules");
        }
        auto lines = std::make_unique<FakeGpioLines>(fakeTime, 0b100,
                                                     std::vector<FakeGpioLines::Change>{});
        lines->sleepWhenIdle();
        return std::unique_ptr<hal::lamp::GpioLines>(std::move(lines));
    };
    hal::lamp::GpioLampSourceOptions options;
    options.lines = {"fakechip", {1, 2, 3}};
    options.reconnectNs = 20 * kMs;
    options.maxWaitNs = 5 * kMs;
    auto src = hal::lamp::makeGpioLampSource(opener, steady, options);
    EXPECT_EQ(src->info().serial, "fakechip:1,2,3");
    const auto got = pollUntil(*src, 2);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_EQ(got[0].lamp, hal::kLampLost) << "the loop must learn that the switch is silent";
    EXPECT_EQ(got[1].lamp, 2) << "after the retry the position read at open";
    EXPECT_EQ(got[1].sequence, got[0].sequence + 1);
    EXPECT_EQ(src->state(), hal::LinkState::Connected);
}

TEST(GpioLampSource, AChipUnpluggedWhileRunningIsReportedLostThenReopened)
{
    hal::SteadyClock steady;
    hal::VirtualClock fakeTime;
    int opens = 0;
    hal::lamp::GpioOpener opener =
            [&](const hal::lamp::GpioLineSpec&) -> Expected<std::unique_ptr<hal::lamp::GpioLines>> {
        ++opens;
        auto lines = std::make_unique<FakeGpioLines>(fakeTime, opens == 1 ? 0b001u : 0b010u,
                                                     std::vector<FakeGpioLines::Change>{});
        lines->sleepWhenIdle();
        if (opens == 1) {
            lines->failFrom(fakeTime.nowNs() + 30 * kMs, "fakechip: waiting for edges failed (No "
                                                         "such device); was the GPIO chip "
                                                         "removed?");
        }
        return std::unique_ptr<hal::lamp::GpioLines>(std::move(lines));
    };
    hal::lamp::GpioLampSourceOptions options;
    options.lines = {"fakechip", {1, 2, 3}};
    options.reconnectNs = 20 * kMs;
    options.maxWaitNs = 5 * kMs;
    auto src = hal::lamp::makeGpioLampSource(opener, steady, options);
    const auto got = pollUntil(*src, 3);
    ASSERT_EQ(got.size(), 3u);
    EXPECT_EQ(got[0].lamp, 0);
    EXPECT_EQ(got[1].lamp, hal::kLampLost) << "the unplugging reaches the loop and the recording";
    EXPECT_EQ(got[2].lamp, 1) << "replugged: the position read at the new open";
    EXPECT_EQ(got[2].sequence, 2u);
}

TEST(LibgpiodLines, AMissingChipIsAClearErrorNamingIt)
{
    auto lines = hal::lamp::libgpiodOpener()({"replica-no-such-gpiochip", {0, 1, 2}});
    ASSERT_FALSE(lines);
    EXPECT_NE(lines.error().message.find("'replica-no-such-gpiochip'"), std::string::npos)
            << lines.error().message;
    EXPECT_NE(lines.error().message.find("not found"), std::string::npos) << lines.error().message;
}

TEST(LibgpiodLines, ListingChipsInAFolderWithoutThemFindsNone)
{
    EXPECT_TRUE(hal::lamp::listGpioChips(REPLICA_SOURCE_DIR).empty());
}

std::vector<hal::LampSample>
simSamples(hal::sim::SimLampSelectorParams p, std::int64_t untilNs, std::int64_t stepNs)
{
    hal::sim::ScenarioParams scenario;
    auto src = hal::sim::makeSimLampSelector(scenario, std::move(p));
    std::vector<hal::LampSample> out;
    for (std::int64_t t = 0; t <= untilNs; t += stepNs) {
        src->poll(t, out);
    }
    return out;
}

TEST(SimLampSelector, FollowsTheScenarioLampsOneDebouncedSamplePerTurn)
{
    hal::sim::ScenarioParams scenario;
    const std::int64_t period = 2'000'000'000;
    const auto got = simSamples({}, 10 * period - 1, 16'666'667);
    ASSERT_EQ(got.size(), 10u); // the position at t = 0, then one per turn
    std::int64_t worst = 0;
    for (std::size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].sequence, k);
        EXPECT_EQ(got[k].lineCount, 3u);
        const std::int64_t turn = static_cast<std::int64_t>(k) * period;
        EXPECT_EQ(got[k].lamp, hal::sim::scenarioAt(scenario, turn).lamp) << "turn " << k;
        if (k > 0) {
            // Debounced: no sooner than the debounce time after the turn, and within the contact
            // bounce (6 ms) after that.
            const std::int64_t latency = got[k].timestampNs - turn;
            EXPECT_GE(latency, 30 * kMs);
            EXPECT_LE(latency, 36 * kMs);
            worst = std::max(worst, latency);
        }
    }
    RecordProperty("worst_debounce_latency_ms", std::to_string(static_cast<double>(worst) * 1e-6));
}

TEST(SimLampSelector, TheSwitchReallyBouncesAndTheDebounceIsWhatRemovesIt)
{
    hal::sim::SimLampSelectorParams raw;
    raw.debounceNs = 0;
    const auto bouncy = simSamples(raw, 2'100'000'000, 100'000);
    // Without debouncing, the turn at 2 s shows as off, the old lamp again, off, the new lamp...
    EXPECT_GT(bouncy.size(), 5u);
    bool sawOff = false;
    for (const auto& s : bouncy) {
        sawOff = sawOff || s.lamp == hal::kLampOff;
    }
    EXPECT_TRUE(sawOff);
    EXPECT_EQ(bouncy.back().lamp, 1);
}

TEST(SimLampSelector, SamplesDoNotDependOnHowOftenTheLoopPolls)
{
    const auto fine = simSamples({}, 6'500'000'000, 1'000'000);
    const auto coarse = simSamples({}, 6'500'000'000, 250'000'000);
    ASSERT_EQ(fine.size(), coarse.size());
    for (std::size_t i = 0; i < fine.size(); ++i) {
        EXPECT_EQ(fine[i].timestampNs, coarse[i].timestampNs);
        EXPECT_EQ(fine[i].lamp, coarse[i].lamp);
        EXPECT_EQ(fine[i].lineLevels, coarse[i].lineLevels);
    }
}

TEST(SimLampSelector, AMisWiredSwitchNamesTheWrongLamp)
{
    hal::sim::SimLampSelectorParams p;
    p.wiring = {0, 2, 1};
    const auto got = simSamples(p, 4'100'000'000, 10'000'000);
    ASSERT_EQ(got.size(), 3u);
    EXPECT_EQ(got[0].lamp, 0);
    EXPECT_EQ(got[1].lamp, 2); // the scenario shows lamp 1
    EXPECT_EQ(got[2].lamp, 1); // ... and then lamp 2
}

} // namespace
} // namespace replica::tests
