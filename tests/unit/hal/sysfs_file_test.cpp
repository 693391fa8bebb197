// Sysfs attributes are read without waiting and within a size: a FIFO, /dev/zero or a directory
// in an attribute's place (a wrong --iio-root, a hostile or broken sysfs) is an error in bounded
// time, for every device that reads them (IIO, the USB spectrometer's serial, HID trackers).
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include <hal/sysfs_file.h>
#include <hal/tracker/hidapi_device.h>

#include <gtest/gtest.h>

namespace replica::hal {
namespace {

namespace fs = std::filesystem;

class SysfsFile : public ::testing::Test
{
protected:
    void SetUp() override
    {
        dir_ = fs::temp_directory_path() / ("replica-sysfs-" + std::to_string(::getpid()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path dir_;
};

TEST_F(SysfsFile, ReadsAValueAndAWholeAttribute)
{
    std::ofstream(dir_ / "value") << "1234\nignored\n";
    auto v = readSysfsFile(dir_ / "value", 64, SysfsRead::FirstLine);
    ASSERT_TRUE(v) << v.error().message;
    EXPECT_EQ(*v, "1234");
    auto whole = readSysfsFile(dir_ / "value", 64, SysfsRead::Whole);
    ASSERT_TRUE(whole) << whole.error().message;
    EXPECT_EQ(*whole, "1234\nignored\n");
    // Exactly at the limit is read; one byte more is refused, naming the file and the limit.
    std::ofstream(dir_ / "limit") << std::string(100, 'x');
    EXPECT_TRUE(readSysfsFile(dir_ / "limit", 100, SysfsRead::Whole));
    auto over = readSysfsFile(dir_ / "limit", 99, SysfsRead::Whole);
    ASSERT_FALSE(over);
    EXPECT_NE(over.error().message.find("limit: more than 99 bytes"), std::string::npos)
            << over.error().message;
}

TEST_F(SysfsFile, AFifoADeviceAndADirectoryAreErrorsInBoundedTime)
{
    ASSERT_EQ(::mkfifo((dir_ / "fifo").c_str(), 0600), 0);
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto what : {SysfsRead::FirstLine, SysfsRead::Whole}) {
        auto fifo = readSysfsFile(dir_ / "fifo", 4096, what);
        ASSERT_FALSE(fifo);
        EXPECT_NE(fifo.error().message.find("no answer within"), std::string::npos)
                << fifo.error().message;
        auto zero = readSysfsFile("/dev/zero", 4096, what);
        ASSERT_FALSE(zero);
        EXPECT_NE(zero.error().message.find("more than 4096 bytes"), std::string::npos)
                << zero.error().message;
        auto dir = readSysfsFile(dir_, 4096, what);
        ASSERT_FALSE(dir);
        EXPECT_NE(dir.error().message.find("cannot be read"), std::string::npos)
                << dir.error().message;
        EXPECT_FALSE(readSysfsFile(dir_ / "missing", 4096, what));
    }
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
}

// A HID device whose report descriptor or uevent is a FIFO (or /dev/zero) is skipped or listed
// without its name, at once: before, the listing (probe, --tracker hid) hung on the FIFO and read
// /dev/zero until memory ran out.
TEST_F(SysfsFile, HidListingNeverWaitsOnAFifoNorReadsADevice)
{
    fs::create_directories(dir_ / "hidraw0" / "device");
    ASSERT_EQ(::mkfifo((dir_ / "hidraw0" / "device" / "report_descriptor").c_str(), 0600), 0);
    fs::create_directories(dir_ / "hidraw1" / "device");
    fs::create_symlink("/dev/zero", dir_ / "hidraw1" / "device" / "report_descriptor");
    const auto t0 = std::chrono::steady_clock::now();
    const auto list = hid::listHidTrackers(dir_, "/dev");
    EXPECT_TRUE(list.empty());
    auto fifo = hid::readSysfsReportDescriptor(dir_ / "hidraw0");
    ASSERT_FALSE(fifo);
    EXPECT_NE(fifo.error().message.find("no answer within"), std::string::npos)
            << fifo.error().message;
    auto zero = hid::readSysfsReportDescriptor(dir_ / "hidraw1");
    ASSERT_FALSE(zero);
    EXPECT_NE(zero.error().message.find("more than 4096 bytes"), std::string::npos)
            << zero.error().message;
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
}

} // namespace
} // namespace replica::hal
