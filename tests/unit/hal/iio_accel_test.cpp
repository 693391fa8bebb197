// The IIO accelerometer against a fake sysfs tree in a temporary directory: attribute layouts
// (shared and per-axis scale, optional offset), bad values, and removal while running.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <hal/accel/iio_accel.h>

#include <gtest/gtest.h>

#include "../support/eventually.h"

namespace replica::tests {
namespace {
namespace fs = std::filesystem;
using hal::accel::IioAccelDevice;

class FakeIio : public ::testing::Test
{
protected:
    void SetUp() override
    {
        root_ = fs::temp_directory_path() /
                ("replica-iio-" +
                 std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
                 ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(root_);
        fs::create_directories(root_ / "iio:device0");
        write("iio:device0/name", "some-adc");
        write("iio:device0/in_voltage0_raw", "12");
        dev_ = root_ / "iio:device1";
        fs::create_directories(dev_);
        write("iio:device1/name", "lis3dh");
        write("iio:device1/in_accel_x_raw", "-12");
        write("iio:device1/in_accel_y_raw", "1000");
        write("iio:device1/in_accel_z_raw", "40");
        write("iio:device1/in_accel_scale", "0.009806650");
    }
    void TearDown() override { fs::remove_all(root_); }
    // Whole or not at all (a rename), as sysfs gives an attribute: the source never reads a
    // half-written file, which it would rightly take for a device fault.
    void write(const std::string& rel, const std::string& text)
    {
        const fs::path tmp = root_ / (rel + ".tmp");
        std::ofstream(tmp) << text << "\n";
        fs::rename(tmp, root_ / rel);
    }
    fs::path root_;
    fs::path dev_;
};

TEST_F(FakeIio, FindsTheAccelerometerAndScalesItsCounts)
{
    auto d = IioAccelDevice::find(root_);
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_EQ(d->name(), "lis3dh");
    auto a = d->read();
    ASSERT_TRUE(a);
    EXPECT_DOUBLE_EQ((*a)[0], -12 * 0.00980665);
    EXPECT_DOUBLE_EQ((*a)[1], 1000 * 0.00980665);
    EXPECT_DOUBLE_EQ((*a)[2], 40 * 0.00980665);
}

TEST_F(FakeIio, PerAxisScaleAndOffsetWin)
{
    write("iio:device1/in_accel_y_scale", "0.02");
    write("iio:device1/in_accel_y_offset", "-10");
    auto d = IioAccelDevice::open(dev_);
    ASSERT_TRUE(d);
    auto a = d->read();
    ASSERT_TRUE(a);
    EXPECT_DOUBLE_EQ((*a)[1], (1000 - 10) * 0.02);
    EXPECT_DOUBLE_EQ((*a)[0], -12 * 0.00980665);
}

TEST_F(FakeIio, BadAttributesNameTheFile)
{
    write("iio:device1/in_accel_z_raw", "4o");
    auto d = IioAccelDevice::open(dev_);
    ASSERT_TRUE(d);
    auto a = d->read();
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().message.find("in_accel_z_raw"), std::string::npos);
    write("iio:device1/in_accel_scale", "0");
    auto z = IioAccelDevice::open(dev_);
    ASSERT_FALSE(z);
    EXPECT_NE(z.error().message.find("not positive"), std::string::npos);
    auto named = IioAccelDevice::find(root_, "bmi160");
    ASSERT_FALSE(named);
    EXPECT_NE(named.error().message.find("bmi160"), std::string::npos);
    auto none = IioAccelDevice::find(root_ / "nowhere");
    ASSERT_FALSE(none);
}

TEST_F(FakeIio, SourceSamplesLosesTheDeviceAndFindsItAgain)
{
    hal::SteadyClock clock;
    hal::accel::IioAccelSourceOptions opt;
    opt.root = root_;
    opt.periodNs = 2'000'000;
    opt.reconnectNs = 10'000'000;
    auto src = hal::accel::makeIioAccelSource(clock, opt);
    std::vector<hal::AccelSample> got;
    ASSERT_TRUE(eventually([&] {
        src->poll(clock.nowNs(), got);
        return got.size() >= 3;
    }));
    // The reading is the reaction to gravity; the sample carries gravity itself.
    EXPECT_DOUBLE_EQ(got[0].gravity.y, -1000 * 0.00980665);
    EXPECT_EQ(got[1].sequence, got[0].sequence + 1);
    // Raw in, processed out: the sysfs values as read, with the scale, offset and mounting.
    ASSERT_TRUE(got[0].raw);
    EXPECT_EQ(got[0].raw->raw, (std::array<double, 3>{-12.0, 1000.0, 40.0}));
    EXPECT_EQ(got[0].raw->scale, (std::array<double, 3>{0.00980665, 0.00980665, 0.00980665}));
    EXPECT_EQ(got[0].raw->offset, (std::array<double, 3>{0.0, 0.0, 0.0}));
    EXPECT_EQ(got[0].raw->axes, "x,y,z");
    const glm::dvec3 again = hal::accel::gravityFromRaw(*got[0].raw, {});
    EXPECT_EQ(again, got[0].gravity);
    fs::remove_all(dev_);
    ASSERT_TRUE(eventually([&] { return src->state() == hal::LinkState::Lost; }));
    fs::create_directories(dev_);
    write("iio:device1/name", "lis3dh");
    write("iio:device1/in_accel_x_raw", "0");
    write("iio:device1/in_accel_y_raw", "0");
    write("iio:device1/in_accel_z_raw", "1000");
    write("iio:device1/in_accel_scale", "0.00980665");
    ASSERT_TRUE(eventually([&] { return src->state() == hal::LinkState::Connected; }));
    got.clear();
    ASSERT_TRUE(eventually([&] {
        src->poll(clock.nowNs(), got);
        return !got.empty() && got.back().gravity.z < -9.0;
    }));
}

// A value file that exists but reads empty, junk or nothing at all (EIO from a glitching I2C
// sensor) must not spin: the source reports Lost, logs once per new error, retries at the
// reconnect period, and stops promptly when destroyed even in the middle of a long retry wait.
TEST_F(FakeIio, FailingValueFileBacksOffLogsOnceAndStops)
{
    for (const std::string bad : {"", "junk", "\x01\x02"}) {
        write("iio:device1/in_accel_y_raw", bad);
        std::ostringstream captured;
        auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
        auto log = std::make_shared<spdlog::logger>("hal.accel", sink);
        spdlog::drop("hal.accel");
        spdlog::register_logger(log);
        hal::SteadyClock clock;
        hal::accel::IioAccelSourceOptions opt;
        opt.root = root_;
        opt.periodNs = 1'000'000;
        opt.reconnectNs = 20'000'000; // 20 ms: ~15 retries in the 300 ms below
        auto src = hal::accel::makeIioAccelSource(clock, opt);
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        EXPECT_EQ(src->state(), hal::LinkState::Lost) << "value '" << bad << "'";
        std::vector<hal::AccelSample> got;
        src->poll(clock.nowNs(), got);
        EXPECT_TRUE(got.empty());
        src.reset();
        spdlog::drop("hal.accel");
        const std::string text = captured.str();
        const auto lines = std::count(text.begin(), text.end(), '\n');
        // One line on finding the device, one on the first failed read; a busy loop logged
        // thousands here.
        EXPECT_LE(lines, 2) << text;
        EXPECT_NE(text.find("in_accel_y_raw"), std::string::npos) << text;
    }
    // A long retry wait is interrupted by stop: destroying the source does not wait it out.
    hal::SteadyClock clock;
    hal::accel::IioAccelSourceOptions opt;
    opt.root = root_;
    opt.reconnectNs = 3'600'000'000'000; // an hour
    auto src = hal::accel::makeIioAccelSource(clock, opt);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto t0 = std::chrono::steady_clock::now();
    src.reset();
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(60));
}

// A driver's range change (2 g to 4 g) changes in_accel_scale while the device stays open: the
// source reads it again (attributesNs) and the next samples carry the new scale, gravity still
// right. Before, the scale was read once at open and a range change halved gravity silently.
TEST_F(FakeIio, FollowsAScaleChangeWhileOpen)
{
    std::ostringstream captured;
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
    spdlog::drop("hal.accel");
    spdlog::register_logger(std::make_shared<spdlog::logger>("hal.accel", sink));
    hal::SteadyClock clock;
    hal::accel::IioAccelSourceOptions opt;
    opt.root = root_;
    opt.periodNs = 2'000'000;
    opt.attributesNs = 20'000'000;
    auto src = hal::accel::makeIioAccelSource(clock, opt);
    std::vector<hal::AccelSample> got;
    ASSERT_TRUE(eventually([&] {
        src->poll(clock.nowNs(), got);
        return !got.empty();
    }));
    EXPECT_DOUBLE_EQ(got.back().gravity.y, -1000 * 0.00980665);
    // The new range: twice the scale, half the counts for the same gravity.
    write("iio:device1/in_accel_y_raw", "500");
    write("iio:device1/in_accel_scale", "0.019613300");
    ASSERT_TRUE(eventually([&] {
        got.clear();
        src->poll(clock.nowNs(), got);
        return !got.empty() && got.back().raw->scale[1] == 0.0196133;
    }));
    EXPECT_DOUBLE_EQ(got.back().gravity.y, -500 * 0.0196133);
    EXPECT_EQ(src->state(), hal::LinkState::Connected);
    // A scale that turns unusable (0, NaN, inf) is a device fault: Lost, one line naming it.
    write("iio:device1/in_accel_scale", "nan");
    ASSERT_TRUE(eventually([&] { return src->state() == hal::LinkState::Lost; }));
    src.reset();
    spdlog::drop("hal.accel");
    const std::string text = captured.str();
    EXPECT_NE(text.find("scale 0.00980665,0.00980665,0.00980665 -> 0.0196133,0.0196133,0.0196133"),
              std::string::npos)
            << text;
    EXPECT_NE(text.find("accelerometer scale nan is not positive or not finite"), std::string::npos)
            << text;
}

// A reading that is not finite ("nan" from a driver, or a product that overflows) is counted and
// logged at a bounded rate, not used, and not one line per sample. Before, it reached the
// estimator as a NaN gravity without a word.
TEST_F(FakeIio, NonFiniteReadingsAreCountedAndLoggedAtABoundedRate)
{
    std::ostringstream captured;
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
    spdlog::drop("hal.accel");
    spdlog::register_logger(std::make_shared<spdlog::logger>("hal.accel", sink));
    write("iio:device1/in_accel_y_raw", "nan");
    hal::SteadyClock clock;
    hal::accel::IioAccelSourceOptions opt;
    opt.root = root_;
    opt.periodNs = 1'000'000;        // 1 kHz: ~300 readings below
    opt.logIntervalNs = 100'000'000; // a line per 100 ms at most
    auto src = hal::accel::makeIioAccelSource(clock, opt);
    std::this_thread::sleep_for(std::chrono::milliseconds(350));
    std::vector<hal::AccelSample> got;
    src->poll(clock.nowNs(), got);
    EXPECT_TRUE(got.empty()) << "a NaN reading was used";
    // Good again: samples flow, with consecutive sequence numbers.
    write("iio:device1/in_accel_y_raw", "1000");
    ASSERT_TRUE(eventually([&] {
        src->poll(clock.nowNs(), got);
        return got.size() >= 2;
    }));
    EXPECT_DOUBLE_EQ(got.back().gravity.y, -1000 * 0.00980665);
    src.reset();
    spdlog::drop("hal.accel");
    const std::string text = captured.str();
    const auto lines = std::count(text.begin(), text.end(), '\n');
    // The find line, the first NaN at once, then one per 100 ms of the 350 ms (and one more for
    // the last ones, reported when the readings are good again): 6 at most; one per sample was 300.
    EXPECT_GE(lines, 3) << text;
    EXPECT_LE(lines, 6) << text;
    EXPECT_NE(text.find("1 reading not finite (the last: raw -12,nan,40"), std::string::npos)
            << text;
    EXPECT_NE(text.find(" readings not finite"), std::string::npos) << "no count > 1: " << text;
    // The line that comes with the good reading names the last bad one, not the good one.
    EXPECT_EQ(text.find("raw -12,1000,40"), std::string::npos) << text;
}

// A reading out of range (a sensor stuck at zero: 0.04 g; a knock or a wrong scale: 10 g) is
// counted and logged at a bounded rate like a NaN, and not used. Before, it reached the estimator.
TEST_F(FakeIio, OutOfRangeReadingsAreCountedAndLoggedAtABoundedRate)
{
    for (const std::string y : {"0", "10000"}) { // |g| 0.41 and 98 m/s^2
        std::ostringstream captured;
        auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(captured);
        spdlog::drop("hal.accel");
        spdlog::register_logger(std::make_shared<spdlog::logger>("hal.accel", sink));
        write("iio:device1/in_accel_y_raw", y);
        hal::SteadyClock clock;
        hal::accel::IioAccelSourceOptions opt;
        opt.root = root_;
        opt.periodNs = 1'000'000;        // 1 kHz: ~300 readings below
        opt.logIntervalNs = 100'000'000; // a line per 100 ms at most
        auto src = hal::accel::makeIioAccelSource(clock, opt);
        std::this_thread::sleep_for(std::chrono::milliseconds(350));
        std::vector<hal::AccelSample> got;
        src->poll(clock.nowNs(), got);
        EXPECT_TRUE(got.empty()) << "an out-of-range reading was used: y raw " << y;
        write("iio:device1/in_accel_y_raw", "1000");
        ASSERT_TRUE(eventually([&] {
            src->poll(clock.nowNs(), got);
            return got.size() >= 2;
        }));
        EXPECT_DOUBLE_EQ(got.back().gravity.y, -1000 * 0.00980665);
        src.reset();
        spdlog::drop("hal.accel");
        const std::string text = captured.str();
        const auto lines = std::count(text.begin(), text.end(), '\n');
        EXPECT_GE(lines, 3) << text;
        EXPECT_LE(lines, 6) << text;
        EXPECT_NE(text.find("1 reading out of range (the last: "), std::string::npos) << text;
        EXPECT_NE(text.find("raw -12," + y + ",40"), std::string::npos) << text;
        EXPECT_NE(text.find(" readings out of range"), std::string::npos) << "no count: " << text;
        EXPECT_EQ(text.find("raw -12,1000,40"), std::string::npos) << text;
    }
}

// A FIFO in place of a value file (or a device that never answers) does not hold the source's
// thread: the read gives up after kSysfsWaitMs, the device is Lost and the source stops promptly.
// Before, the open waited for a writer without end and held SIGTERM with it.
TEST_F(FakeIio, AFifoValueFileNeverBlocks)
{
    fs::remove(dev_ / "in_accel_y_raw");
    ASSERT_EQ(::mkfifo((dev_ / "in_accel_y_raw").c_str(), 0600), 0);
    const auto t0 = std::chrono::steady_clock::now();
    auto v = hal::accel::readSysfsNumber(dev_ / "in_accel_y_raw");
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
    ASSERT_FALSE(v);
    EXPECT_NE(v.error().message.find("no answer within"), std::string::npos) << v.error().message;
    hal::SteadyClock clock;
    hal::accel::IioAccelSourceOptions opt;
    opt.root = root_;
    opt.periodNs = 1'000'000;
    opt.reconnectNs = 20'000'000;
    auto src = hal::accel::makeIioAccelSource(clock, opt);
    ASSERT_TRUE(eventually([&] { return src->state() == hal::LinkState::Lost; }));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(src->state(), hal::LinkState::Lost);
    const auto t1 = std::chrono::steady_clock::now();
    src.reset();
    EXPECT_LT(std::chrono::steady_clock::now() - t1, std::chrono::seconds(5));
}

TEST(AxisMapping, ParsesSignedPermutationsAndRejectsTheRest)
{
    auto m = hal::accel::parseAxisMapping("-y,x,z");
    ASSERT_TRUE(m) << m.error().message;
    // Sensor reads (1, 2, 3): panel x = -(-y) = 2, panel y = -x = -1, panel z = -z = -3.
    const glm::dvec3 g = hal::accel::gravityInPanel({1.0, 2.0, 3.0}, *m);
    EXPECT_DOUBLE_EQ(g.x, 2.0);
    EXPECT_DOUBLE_EQ(g.y, -1.0);
    EXPECT_DOUBLE_EQ(g.z, -3.0);
    for (const char* bad : {"x,y", "x,x,z", "x,y,w", "x,y,z,x", "", "xy,z,", "--x,y,z"}) {
        auto e = hal::accel::parseAxisMapping(bad);
        EXPECT_FALSE(e) << bad;
    }
}

} // namespace
} // namespace replica::tests
