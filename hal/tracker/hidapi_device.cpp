// hidapi (hidraw backend) implementation of HidDevice, and the sysfs list of HID trackers.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <sstream>

#include <fmt/format.h>
#include <hidapi/hidapi.h>
#include <unistd.h>

#include <hal/sysfs_file.h>
#include <hal/tracker/hid_descriptor.h>
#include <hal/tracker/hid_eye_head.h>
#include <hal/tracker/hidapi_device.h>

namespace replica::hal::hid {
namespace {

std::string narrow(const wchar_t* w)
{
    std::string s;
    for (; w != nullptr && *w != 0; ++w) {
        s += *w < 128 ? static_cast<char>(*w) : '?';
    }
    return s;
}

bool hidInit()
{
    static std::once_flag once;
    static bool ok = false;
    std::call_once(once, [] { ok = hid_init() == 0; });
    return ok;
}

class HidapiDevice final : public HidDevice
{
public:
    HidapiDevice(hid_device* dev, HidrawNode node) : dev_(dev), node_(std::move(node)) {}
    ~HidapiDevice() override { hid_close(dev_); }
    HidapiDevice(const HidapiDevice&) = delete;
    HidapiDevice& operator=(const HidapiDevice&) = delete;

    Expected<std::vector<std::uint8_t>> reportDescriptor() override
    {
        return readSysfsReportDescriptor(node_.sysfsDir);
    }

    HidResult readInput(std::span<std::uint8_t> buffer, int timeoutMs) override
    {
        const int n = hid_read_timeout(dev_, buffer.data(), buffer.size(), timeoutMs);
        if (n < 0) {
            // hidraw reports an unplugged device as a poll error or ENODEV.
            return {::access(node_.devNode.c_str(), F_OK) == 0 ? HidStatus::Io : HidStatus::Gone,
                    0};
        }
        return {n == 0 ? HidStatus::Timeout : HidStatus::Ok, static_cast<std::size_t>(n)};
    }

    HidResult getFeature(std::uint8_t reportId, std::span<std::uint8_t> buffer) override
    {
        if (buffer.empty()) {
            return {HidStatus::Io, 0};
        }
        buffer[0] = reportId;
        const int n = hid_get_feature_report(dev_, buffer.data(), buffer.size());
        if (n < 0) {
            return {::access(node_.devNode.c_str(), F_OK) == 0 ? HidStatus::Io : HidStatus::Gone,
                    0};
        }
        return {HidStatus::Ok, static_cast<std::size_t>(n)};
    }

    HidStatus sendFeature(std::span<const std::uint8_t> report) override
    {
        const int n = hid_send_feature_report(dev_, report.data(), report.size());
        if (n < 0) {
            return ::access(node_.devNode.c_str(), F_OK) == 0 ? HidStatus::Io : HidStatus::Gone;
        }
        return HidStatus::Ok;
    }

    std::string describe() const override
    {
        return fmt::format("{} ({:04x}:{:04x} {})", node_.devNode, node_.vendor, node_.product,
                           node_.name);
    }

private:
    hid_device* dev_;
    HidrawNode node_;
};

// A HID device's uevent: DRIVER, HID_ID, HID_NAME, HID_PHYS, HID_UNIQ, MODALIAS (a few hundred
// bytes; sysfs gives at most a page).
constexpr std::size_t kMaxUeventBytes = 4096;

// HID_ID=0003:0000046D:0000C52B and HID_NAME=... from the HID device's uevent.
void readUevent(const std::filesystem::path& file, HidrawNode& n)
{
    // A uevent is a few hundred bytes; a FIFO or a device in its place is never waited for.
    std::istringstream in(readSysfsFile(file, kMaxUeventBytes, SysfsRead::Whole).value_or(""));
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("HID_NAME=", 0) == 0) {
            n.name = line.substr(9);
        } else if (line.rfind("HID_ID=", 0) == 0) {
            unsigned bus = 0;
            unsigned vid = 0;
            unsigned pid = 0;
            if (std::sscanf(line.c_str() + 7, "%x:%x:%x", &bus, &vid, &pid) == 3) {
                n.vendor = static_cast<std::uint16_t>(vid);
                n.product = static_cast<std::uint16_t>(pid);
            }
        }
    }
}

} // namespace

const char* toString(HidStatus s)
{
    switch (s) {
    case HidStatus::Ok:
        return "ok";
    case HidStatus::Timeout:
        return "timeout";
    case HidStatus::Gone:
        return "device gone";
    case HidStatus::Io:
        return "I/O error";
    }
    return "unknown";
}

Expected<std::vector<std::uint8_t>> readSysfsReportDescriptor(const std::filesystem::path& sysfsDir)
{
    const auto file = sysfsDir / "device" / "report_descriptor";
    // At most the kernel's HID_MAX_DESCRIPTOR_SIZE, read without waiting: a FIFO, /dev/zero or a
    // directory in its place is an error in bounded time.
    auto read = readSysfsFile(file, kMaxDescriptorBytes, SysfsRead::Whole);
    if (!read) {
        return makeError(read.error().code, fmt::format("cannot read the HID report descriptor: {}",
                                                        read.error().message));
    }
    return std::vector<std::uint8_t>(read->begin(), read->end());
}

std::vector<HidrawNode> listHidTrackers(const std::filesystem::path& sysfsRoot,
                                        const std::filesystem::path& devRoot)
{
    std::vector<HidrawNode> found;
    std::error_code ec;
    std::vector<std::filesystem::path> dirs;
    for (const auto& e : std::filesystem::directory_iterator(sysfsRoot, ec)) {
        if (e.path().filename().string().rfind("hidraw", 0) == 0) {
            dirs.push_back(e.path());
        }
    }
    std::sort(dirs.begin(), dirs.end());
    for (const auto& dir : dirs) {
        HidrawNode n;
        n.sysfsDir = dir;
        n.devNode = (devRoot / dir.filename()).string();
        auto bytes = readSysfsReportDescriptor(dir);
        if (!bytes) {
            continue;
        }
        auto d = parseReportDescriptor(*bytes);
        if (!d) {
            // Only trackers matter here; a broken descriptor of page 0x12 is worth reporting.
            bool mentions = false; // a Usage Page (0x12) item somewhere
            for (std::size_t i = 0; i + 1 < bytes->size(); ++i) {
                mentions = mentions || ((*bytes)[i] == 0x05 && (*bytes)[i + 1] == 0x12);
            }
            if (!mentions) {
                continue;
            }
            n.error = d.error().message;
        } else {
            auto l = eht::findLayout(*d);
            if (!l && l.error().message.rfind("not an eye or head tracker", 0) == 0) {
                continue;
            }
            if (l) {
                n.layout = l->summary();
            } else {
                n.error = l.error().message;
            }
        }
        readUevent(dir / "device" / "uevent", n);
        found.push_back(std::move(n));
    }
    return found;
}

HidOpener
hidapiOpener(std::string devNode, std::filesystem::path sysfsRoot, std::filesystem::path devRoot)
{
    return [devNode = std::move(devNode), sysfsRoot = std::move(sysfsRoot),
            devRoot = std::move(devRoot)]() -> Expected<std::unique_ptr<HidDevice>> {
        HidrawNode node;
        const auto trackers = listHidTrackers(sysfsRoot, devRoot);
        bool known = false;
        for (const auto& t : trackers) {
            if ((devNode.empty() && t.error.empty()) || t.devNode == devNode) {
                node = t;
                known = true;
                break;
            }
        }
        if (!known) {
            if (devNode.empty()) {
                return makeError(ErrorCode::NotFound,
                                 fmt::format("no HID eye/head tracker (usage page 0x12) under {}: "
                                             "check the cable, or use --tracker opentrack",
                                             sysfsRoot.string()));
            }
            // A node named by the user that is not (or no longer) a tracker.
            node.devNode = devNode;
            node.sysfsDir = sysfsRoot / std::filesystem::path(devNode).filename();
            if (!std::filesystem::exists(node.sysfsDir)) {
                return makeError(ErrorCode::NotFound,
                                 fmt::format("{}: no such HID device: check the cable and "
                                             "`ls /sys/class/hidraw`",
                                             devNode));
            }
            readUevent(node.sysfsDir / "device" / "uevent", node);
        }
        if (!hidInit()) {
            return makeError(ErrorCode::Io, "hidapi could not start (hid_init failed)");
        }
        hid_device* dev = hid_open_path(node.devNode.c_str());
        if (dev == nullptr) {
            const int err = errno;
            if (err == EACCES || err == EPERM) {
                return makeError(ErrorCode::Io,
                                 fmt::format("{}: permission denied: install deploy/udev/"
                                             "60-replica.rules, add the user to 'plugdev' and "
                                             "replug the tracker",
                                             node.devNode));
            }
            return makeError(err == ENOENT ? ErrorCode::NotFound : ErrorCode::Io,
                             fmt::format("{}: hidapi cannot open it: {}", node.devNode,
                                         narrow(hid_error(nullptr))));
        }
        return std::unique_ptr<HidDevice>(std::make_unique<HidapiDevice>(dev, node));
    };
}

} // namespace replica::hal::hid
