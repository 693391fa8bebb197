// The HID seam under the head-tracker driver: one opened HID device's report descriptor, input
// reports and feature reports, with hidapi's conventions. The live implementation is hidapi's
// hidraw backend (hidapi_device.h); tests put a byte-level fake behind it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::hal::hid {

enum class HidStatus {
    Ok,
    Timeout, // no report within the timeout
    Gone,    // unplugged: reopen later
    Io,      // anything else
};

const char* toString(HidStatus s);

struct HidResult {
    HidStatus status = HidStatus::Ok;
    std::size_t bytes = 0;
};

class HidDevice
{
public:
    virtual ~HidDevice() = default;
    virtual Expected<std::vector<std::uint8_t>> reportDescriptor() = 0;
    // One input report, as hidapi's hid_read_timeout gives it: the report ID first only when the
    // device numbers its reports.
    virtual HidResult readInput(std::span<std::uint8_t> buffer, int timeoutMs) = 0;
    // A feature report: on return buffer[0] is the report ID (0 when not numbered) and the data
    // follows; bytes counts the ID byte (hid_get_feature_report).
    virtual HidResult getFeature(std::uint8_t reportId, std::span<std::uint8_t> buffer) = 0;
    // report[0]: the report ID, 0 when not numbered (hid_send_feature_report).
    virtual HidStatus sendFeature(std::span<const std::uint8_t> report) = 0;
    // Where the device is, for messages: "/dev/hidraw3 (2104:0313 Tobii Eye Tracker)".
    virtual std::string describe() const = 0;
};

// Opens the device, or says why not (NotFound while it is unplugged).
using HidOpener = std::function<Expected<std::unique_ptr<HidDevice>>()>;

} // namespace replica::hal::hid
