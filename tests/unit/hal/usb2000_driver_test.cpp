// The USB2000+ driver against a byte-level fake of the device: command bytes, EEPROM parsing,
// spectrum decoding, stale-exposure discard, resynchronisation and unplugging.
#include <chrono>
#include <clocale>
#include <thread>

#include <hal/spectrometer/usb2000_device.h>
#include <hal/spectrometer/usb2000_protocol.h>
#include <hal/spectrometer/usb2000_source.h>

#include <gtest/gtest.h>

#include "../support/eventually.h"
#include "fake_usb2000.h"

namespace replica::tests {
namespace {

using hal::spectrometer::Usb2000Device;
namespace usb2000 = hal::spectrometer::usb2000;

std::unique_ptr<Usb2000Device> openFake(const std::shared_ptr<FakeUsb2000State>& state)
{
    auto dev = Usb2000Device::open(std::make_unique<FakeUsb2000>(state));
    EXPECT_TRUE(dev) << (dev ? "" : dev.error().message);
    return dev ? std::move(*dev) : nullptr;
}

TEST(Usb2000Protocol, CommandBytesAreTheDevicesLayout)
{
    EXPECT_EQ(usb2000::initialise(), (std::vector<std::uint8_t>{0x01}));
    // 100 ms = 100 000 us = 0x000186A0, little-endian after the opcode.
    EXPECT_EQ(usb2000::setIntegrationTime(100'000),
              (std::vector<std::uint8_t>{0x02, 0xA0, 0x86, 0x01, 0x00}));
    EXPECT_EQ(usb2000::querySlot(17), (std::vector<std::uint8_t>{0x05, 0x11}));
    EXPECT_EQ(usb2000::requestSpectrum(), (std::vector<std::uint8_t>{0x09}));
    EXPECT_EQ(usb2000::setTriggerMode(3), (std::vector<std::uint8_t>{0x0A, 0x03, 0x00}));
}

TEST(Usb2000Protocol, IntegrationTimeIsClampedAndStepped)
{
    EXPECT_EQ(usb2000::clampIntegrationUs(0), 1'000u);
    EXPECT_EQ(usb2000::clampIntegrationUs(1'499), 1'000u);
    EXPECT_EQ(usb2000::clampIntegrationUs(1'500), 2'000u);
    EXPECT_EQ(usb2000::clampIntegrationUs(123'456), 123'000u);
    EXPECT_EQ(usb2000::clampIntegrationUs(10'000'000'000ULL), 65'000'000u);
}

TEST(Usb2000Protocol, StatusReplyFields)
{
    std::vector<std::uint8_t> r(16, 0);
    r[0] = 0x00;
    r[1] = 0x08; // 2048 pixels
    r[2] = 0x40;
    r[3] = 0x0D;
    r[4] = 0x03; // 200 000 us
    r[9] = 9;
    r[14] = 0x80;
    auto s = usb2000::parseStatus(r);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->pixels, 2048);
    EXPECT_EQ(s->integrationTimeUs, 200'000u);
    EXPECT_EQ(s->packetsPerSpectrum, 9);
    EXPECT_TRUE(s->highSpeed);
    r.pop_back();
    EXPECT_FALSE(usb2000::parseStatus(r));
}

TEST(Usb2000Protocol, SpectrumNeedsItsSyncByteAndLength)
{
    std::vector<std::uint8_t> b(4097, 0);
    b[0] = 0x34;
    b[1] = 0x12;
    b[4094] = 0xFF;
    b[4095] = 0xFF;
    b[4096] = 0x69;
    auto c = usb2000::parseSpectrum(b);
    ASSERT_TRUE(c);
    EXPECT_EQ((*c)[0], 0x1234);
    EXPECT_EQ((*c)[2047], 0xFFFF);
    b[4096] = 0x68;
    auto bad = usb2000::parseSpectrum(b);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("sync"), std::string::npos);
    b.resize(4096);
    EXPECT_FALSE(usb2000::parseSpectrum(b));
}

TEST(Usb2000Protocol, SlotNumbersIgnoreTheProcessLocale)
{
    const std::string text = "3.5e-06";
    std::vector<std::uint8_t> data(text.begin(), text.end());
    data.resize(15, 0);
    // A comma-decimal locale must not change the parse (where the machine has one).
    const char* old = std::setlocale(LC_NUMERIC, nullptr);
    const std::string saved = old != nullptr ? old : "C";
    std::setlocale(LC_NUMERIC, "de_DE.UTF-8");
    auto v = usb2000::slotNumber(data, 6);
    std::setlocale(LC_NUMERIC, saved.c_str());
    ASSERT_TRUE(v);
    EXPECT_DOUBLE_EQ(*v, 3.5e-6);
    const std::string junk = "12,5abc";
    std::vector<std::uint8_t> bad(junk.begin(), junk.end());
    auto e = usb2000::slotNumber(bad, 3);
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().message.find("slot 3"), std::string::npos);
}

TEST(Usb2000Device, OpenReadsTheCalibrationFromTheEeprom)
{
    auto state = std::make_shared<FakeUsb2000State>();
    state->saturation = 62'000;
    auto dev = openFake(state);
    ASSERT_TRUE(dev);
    const auto& cal = dev->calibration();
    EXPECT_EQ(cal.serial, "USB2+F00001");
    EXPECT_DOUBLE_EQ(cal.wavelengthCoeffs[0], 339.2);
    EXPECT_DOUBLE_EQ(cal.wavelengthCoeffs[1], 0.3797);
    EXPECT_DOUBLE_EQ(cal.wavelengthCoeffs[2], -1.62e-5);
    EXPECT_DOUBLE_EQ(cal.wavelengthCoeffs[3], -1.3e-10);
    EXPECT_EQ(cal.nonlinearityOrder, 1);
    EXPECT_DOUBLE_EQ(cal.nonlinearityCoeffs[0], 1.0);
    EXPECT_DOUBLE_EQ(cal.nonlinearityCoeffs[1], -2e-6);
    EXPECT_DOUBLE_EQ(cal.nonlinearityCoeffs[2], 0.0); // above the programmed order
    EXPECT_EQ(cal.saturationCounts, 62'000);
    EXPECT_TRUE(state->initialised);
    EXPECT_EQ(state->triggerMode, 0); // free running
    EXPECT_GE(state->haltsCleared, 3);
    EXPECT_EQ(state->commands.front(), usb2000::initialise());
}

TEST(Usb2000Device, UnprogrammedSaturationMeansFullScale)
{
    auto state = std::make_shared<FakeUsb2000State>();
    auto dev = openFake(state);
    ASSERT_TRUE(dev);
    EXPECT_EQ(dev->calibration().saturationCounts, 65535);
}

TEST(Usb2000Device, DamagedEepromIsADeviceErrorNamingTheSlot)
{
    auto state = std::make_shared<FakeUsb2000State>();
    state->eeprom[2] = "0,3797";
    auto dev = Usb2000Device::open(std::make_unique<FakeUsb2000>(state));
    ASSERT_FALSE(dev);
    EXPECT_EQ(dev.error().code, ErrorCode::DeviceFailure);
    EXPECT_NE(dev.error().message.find("slot 2"), std::string::npos) << dev.error().message;

    auto garbled = std::make_shared<FakeUsb2000State>();
    garbled->garbleSlotEcho = true;
    auto dev2 = Usb2000Device::open(std::make_unique<FakeUsb2000>(garbled));
    ASSERT_FALSE(dev2);
    EXPECT_NE(dev2.error().message.find("malformed"), std::string::npos);
}

TEST(Usb2000Device, FirstSpectrumAfterAnIntegrationChangeIsDiscarded)
{
    auto state = std::make_shared<FakeUsb2000State>();
    auto dev = openFake(state);
    ASSERT_TRUE(dev);
    auto first = dev->readSpectrum(); // 100 ms from open
    ASSERT_TRUE(first);
    EXPECT_EQ(first->counts[100], 1000 + 100);
    ASSERT_TRUE(dev->setIntegrationTime(250'400)); // stepped to 250 ms
    EXPECT_EQ(state->integrationUs, 250'000u);
    const int served = state->spectraServed;
    auto s = dev->readSpectrum();
    ASSERT_TRUE(s);
    EXPECT_EQ(state->spectraServed, served + 2); // one stale spectrum read and thrown away
    EXPECT_EQ(s->integrationTimeUs, 250'000u);
    EXPECT_EQ(s->counts[100], 1000 + 250); // exposed with the new time
    EXPECT_GE(dev->discardedCount(), 1);
}

TEST(Usb2000Device, SaturationIsJudgedAgainstTheEepromLevel)
{
    auto state = std::make_shared<FakeUsb2000State>();
    state->saturation = 60'000;
    state->counts = [](std::uint32_t) {
        std::vector<std::uint16_t> c(2048, 2000);
        c[1200] = 60'000;
        return c;
    };
    auto dev = openFake(state);
    ASSERT_TRUE(dev);
    auto s = dev->readSpectrum();
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->saturated);
    state->counts = [](std::uint32_t) { return std::vector<std::uint16_t>(2048, 59'999); };
    auto t = dev->readSpectrum();
    ASSERT_TRUE(t);
    EXPECT_FALSE(t->saturated);
}

TEST(Usb2000Device, LostSyncIsReportedThenRecovered)
{
    auto state = std::make_shared<FakeUsb2000State>();
    auto dev = openFake(state);
    ASSERT_TRUE(dev);
    ASSERT_TRUE(dev->readSpectrum());
    state->badSyncOnce = 1;
    auto bad = dev->readSpectrum();
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("sync"), std::string::npos);
    EXPECT_EQ(dev->resyncCount(), 1);
    state->shortSpectrumOnce = 1;
    EXPECT_FALSE(dev->readSpectrum());
    EXPECT_EQ(dev->resyncCount(), 2);
    auto good = dev->readSpectrum();
    ASSERT_TRUE(good) << good.error().message;
    EXPECT_EQ(good->counts.size(), 2048u);
}

TEST(Usb2000Device, UnpluggingIsNotFound)
{
    auto state = std::make_shared<FakeUsb2000State>();
    auto dev = openFake(state);
    ASSERT_TRUE(dev);
    state->unplugged = true;
    auto s = dev->readSpectrum();
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().code, ErrorCode::NotFound);
    EXPECT_NE(s.error().message.find("unplugged"), std::string::npos);
}

TEST(Usb2000Source, DeliversStampedSpectraFollowsAutoIntegrationAndSurvivesUnplugging)
{
    auto state = std::make_shared<FakeUsb2000State>();
    bool plugged = true;
    std::mutex m;
    auto opener = [&]() -> Expected<std::unique_ptr<hal::spectrometer::UsbTransport>> {
        std::lock_guard lock(m);
        if (!plugged) {
            return makeError(ErrorCode::NotFound, "no USB device 2457:101e found");
        }
        state->unplugged = false;
        return std::unique_ptr<hal::spectrometer::UsbTransport>(
                std::make_unique<FakeUsb2000>(state));
    };
    hal::SteadyClock clock;
    hal::spectrometer::Usb2000SourceOptions opt;
    opt.periodNs = 5'000'000;
    opt.reconnectNs = 10'000'000;
    opt.initialIntegrationUs = 20'000;
    // A stand-in controller: ask for 30 ms once anything has been seen.
    opt.nextIntegrationUs = [](const hal::SpectrumSample&) { return 30'000u; };
    auto src = hal::spectrometer::makeUsb2000Source(opener, clock, opt);

    std::vector<hal::SpectrumSample> got;
    ASSERT_TRUE(eventually([&] {
        src->poll(clock.nowNs(), got);
        return got.size() >= 4;
    }));
    EXPECT_EQ(src->state(), hal::LinkState::Connected);
    EXPECT_EQ(got.front().counts.size(), 2048u);
    EXPECT_DOUBLE_EQ(got.front().wavelengthCoeffs[1], 0.3797);
    for (std::size_t i = 1; i < got.size(); ++i) {
        EXPECT_GT(got[i].timestampNs, got[i - 1].timestampNs);
        EXPECT_EQ(got[i].sequence, got[i - 1].sequence + 1);
    }
    EXPECT_EQ(got.back().integrationTimeUs, 30'000u);
    EXPECT_EQ(got.back().counts[0], 1000 + 30);

    {
        std::lock_guard lock(m);
        plugged = false;
        state->unplugged = true;
    }
    ASSERT_TRUE(eventually([&] { return src->state() == hal::LinkState::Lost; }));
    {
        std::lock_guard lock(m);
        plugged = true;
    }
    ASSERT_TRUE(eventually([&] { return src->state() == hal::LinkState::Connected; }));
    const auto before = got.size();
    ASSERT_TRUE(eventually([&] {
        src->poll(clock.nowNs(), got);
        return got.size() > before + 1;
    }));
}

} // namespace
} // namespace replica::tests
