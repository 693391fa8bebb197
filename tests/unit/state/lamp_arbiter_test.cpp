// The lamp selector and the classifier together: a turn of the switch shows at once, agreement
// keeps it, a lasting disagreement hands the light back to the spectrometer with one warning, and
// "off"/"lost"/no selector leave today's classifier behaviour untouched.
#include <algorithm>

#include <state/lamp_arbiter.h>
#include <state/scene_estimator.h>

#include <hal/sim/sim_devices.h>
#include <platform/appliance.h>

#include <gtest/gtest.h>

#include "../support/shipped_light.h"

namespace replica::state {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

hal::LampSample selectorAt(std::uint32_t seq, int lamp)
{
    hal::LampSample s;
    s.sequence = seq;
    s.lamp = lamp;
    s.lineCount = 3;
    s.lineLevels = lamp >= 0 ? (1u << lamp) : 0u;
    return s;
}

TEST(LampArbiter, WithoutASelectorTheClassifierDecidesAlone)
{
    LampArbiter a(3);
    for (int c : {-1, 0, 0, 2, -1, 1}) {
        EXPECT_EQ(a.onClassified(c, 0), c);
    }
    EXPECT_EQ(a.trustedLamp(), -1);
}

TEST(LampArbiter, ATurnShowsAtOnceAndHoldsWhileTheClassifierConfirms)
{
    LampArbiter a(3, {1 * kS});
    EXPECT_EQ(a.onSelector(selectorAt(0, 2)), 2);
    // The classifier still says the old lamp for a while (its hysteresis), then agrees.
    EXPECT_EQ(a.onClassified(0, 0), 2);
    EXPECT_EQ(a.onClassified(0, kS / 2), 2);
    EXPECT_EQ(a.onClassified(2, kS - 1), 2);
    // Agreement resets the clock: a later short disagreement is tolerated again.
    EXPECT_EQ(a.onClassified(-1, 5 * kS), 2);
    EXPECT_EQ(a.onClassified(-1, 5 * kS + kS - 1), 2);
    EXPECT_EQ(a.overruled(), 0u);
    EXPECT_FALSE(a.takeWarning());
}

TEST(LampArbiter, ALastingDisagreementTrustsTheSpectrometerAndWarnsOnce)
{
    LampArbiter a(3, {1 * kS});
    a.onSelector(selectorAt(0, 1));
    EXPECT_EQ(a.onClassified(2, 10 * kS), 1);
    EXPECT_EQ(a.onClassified(2, 11 * kS - 1), 1);
    EXPECT_EQ(a.onClassified(2, 11 * kS), 2) << "after 1 s of disagreement the spectrometer wins";
    EXPECT_EQ(a.trustedLamp(), -1);
    const auto w = a.takeWarning();
    ASSERT_TRUE(w);
    EXPECT_NE(w->find("mis-wired"), std::string::npos) << *w;
    EXPECT_NE(w->find("--lamp-gpio"), std::string::npos) << *w;
    EXPECT_FALSE(a.takeWarning()) << "taken once";
    // The next turn is trusted again; a second overruling is counted but not warned about again.
    EXPECT_EQ(a.onSelector(selectorAt(1, 0)), 0);
    EXPECT_EQ(a.onClassified(1, 20 * kS), 0);
    EXPECT_EQ(a.onClassified(1, 21 * kS), 1);
    EXPECT_EQ(a.overruled(), 2u);
    EXPECT_FALSE(a.takeWarning());
}

TEST(LampArbiter, OffInvalidLostAndOutOfRangeHandTheLightBackToTheClassifier)
{
    for (int code : {hal::kLampOff, hal::kLampInvalid, hal::kLampLost, 3}) {
        LampArbiter a(3);
        a.onSelector(selectorAt(0, 1));
        EXPECT_FALSE(a.onSelector(selectorAt(1, code))) << code;
        EXPECT_EQ(a.onClassified(2, 0), 2) << code;
        EXPECT_EQ(a.onClassified(-1, 0), -1) << code;
    }
}

// The state stage (SceneEstimator) with the booth's real lamps and simulated spectra of the
// scenario.
class SelectorSceneTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        setup_ = tests::shippedEstimatorSetup();
        hal::sim::SimSpectrometerParams p;
        auto lamps = platform::simLamps(setup_.light.booth);
        ASSERT_TRUE(lamps) << lamps.error().message;
        p.lamps = std::move(*lamps);
        p.responsivityNm = setup_.light.calibration.wavelengthNm;
        p.responsivity = setup_.light.calibration.responsivity;
        // The scenario: lamp 0 for 2 s, lamp 1 for 2 s, lamp 2 ...
        hal::sim::makeSimSpectrometer({}, p)->poll(6 * kS, spectra_);
    }

    // Runs the state stage over the spectra with the given selector samples, at 20 frames a second;
    // returns the lamp shown at each frame.
    std::vector<int> run(SceneEstimator& u, const std::vector<hal::LampSample>& selector) const
    {
        std::vector<int> shown;
        pipeline::scene::SceneState st;
        for (std::int64_t t = 0; t < 6 * kS; t += 50'000'000) {
            const hal::SpectrumSample* s = nullptr;
            for (const auto& x : spectra_) {
                if (x.timestampNs <= t) {
                    s = &x;
                }
            }
            const hal::LampSample* l = nullptr;
            for (const auto& x : selector) {
                if (x.timestampNs <= t) {
                    l = &x;
                }
            }
            u.update(st, s, nullptr, nullptr, l);
            shown.push_back(st.lampIndex);
        }
        return shown;
    }

    SceneEstimatorSetup setup_;
    std::vector<hal::SpectrumSample> spectra_;
};

std::vector<hal::LampSample> simSelector(std::vector<int> wiring)
{
    hal::sim::SimLampSelectorParams p;
    p.wiring = std::move(wiring);
    std::vector<hal::LampSample> out;
    hal::sim::makeSimLampSelector({}, p)->poll(6 * kS, out);
    return out;
}

TEST_F(SelectorSceneTest, TheSwitchShowsTheNewLampBeforeTheClassifierWould)
{
    auto plain = SceneEstimator::create(setup_);
    auto withSwitch = SceneEstimator::create(setup_);
    ASSERT_TRUE(plain && withSwitch);
    const auto before = run(*plain, {});
    const auto after = run(*withSwitch, simSelector({}));
    // Frame 41 is t = 2.05 s: the switch turned at 2 s and settled 30-36 ms later.
    EXPECT_EQ(after[41], 1);
    EXPECT_NE(before[41], 1) << "without the switch the classifier needs several spectra";
    const auto firstAt = [](const std::vector<int>& v, int lamp, std::size_t from) {
        for (std::size_t i = from; i < v.size(); ++i) {
            if (v[i] == lamp) {
                return i;
            }
        }
        return v.size();
    };
    EXPECT_LT(firstAt(after, 1, 40), firstAt(before, 1, 40));
    EXPECT_LT(firstAt(after, 2, 80), firstAt(before, 2, 80));
    // From the start the switch names lamp 0; the classifier alone starts in direct-sensor mode.
    EXPECT_EQ(after[0], 0);
    EXPECT_EQ(withSwitch->lampArbiter().overruled(), 0u) << "switch and light agree";
    // Once the classifier has confirmed, both show the same lamp.
    EXPECT_EQ(after[70], before[70]);
}

TEST_F(SelectorSceneTest, AMisWiredSwitchIsOverruledByTheSpectrometer)
{
    auto u = SceneEstimator::create(setup_);
    ASSERT_TRUE(u);
    const auto shown = run(*u, simSelector({0, 2, 1}));
    EXPECT_EQ(shown[41], 2) << "believed at first: the turn shows at once";
    // 1.5 s of disagreement after the classifier's first contrary answer: the true lamp returns.
    EXPECT_EQ(shown[79], 1) << "t = 3.95 s";
    EXPECT_EQ(u->lampArbiter().overruled(), 1u);
}

TEST_F(SelectorSceneTest, OffLeavesTodaysBehaviour)
{
    auto plain = SceneEstimator::create(setup_);
    auto off = SceneEstimator::create(setup_);
    ASSERT_TRUE(plain && off);
    const auto before = run(*plain, {});
    const auto after = run(*off, {selectorAt(0, hal::kLampOff)});
    EXPECT_EQ(before, after);
}

} // namespace
} // namespace replica::state
