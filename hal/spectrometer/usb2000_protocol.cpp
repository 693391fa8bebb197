// USB2000+ command encoding and reply parsing.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include <hal/spectrometer/usb2000_protocol.h>

namespace replica::hal::spectrometer::usb2000 {
namespace {

void putLe16(std::vector<std::uint8_t>& out, std::uint16_t v)
{
    out.push_back(static_cast<std::uint8_t>(v & 0xFF));
    out.push_back(static_cast<std::uint8_t>(v >> 8));
}

void putLe32(std::vector<std::uint8_t>& out, std::uint32_t v)
{
    for (int shift = 0; shift < 32; shift += 8) {
        out.push_back(static_cast<std::uint8_t>((v >> shift) & 0xFF));
    }
}

std::uint16_t le16(std::span<const std::uint8_t> b, std::size_t at)
{
    return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
}

std::uint32_t le32(std::span<const std::uint8_t> b, std::size_t at)
{
    return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
           (static_cast<std::uint32_t>(b[at + 2]) << 16) |
           (static_cast<std::uint32_t>(b[at + 3]) << 24);
}

} // namespace

std::vector<std::uint8_t> initialise()
{
    return {kInitialise};
}

std::uint32_t clampIntegrationUs(std::uint64_t requestedUs)
{
    const std::uint64_t clamped =
            std::clamp<std::uint64_t>(requestedUs, kMinIntegrationUs, kMaxIntegrationUs);
    const std::uint64_t steps = (clamped + kIntegrationStepUs / 2) / kIntegrationStepUs;
    return static_cast<std::uint32_t>(
            std::min<std::uint64_t>(steps * kIntegrationStepUs, kMaxIntegrationUs));
}

std::vector<std::uint8_t> setIntegrationTime(std::uint32_t us)
{
    std::vector<std::uint8_t> out{kSetIntegrationTime};
    putLe32(out, clampIntegrationUs(us));
    return out;
}

std::vector<std::uint8_t> querySlot(std::uint8_t slot)
{
    return {kQuerySlot, slot};
}

std::vector<std::uint8_t> requestSpectrum()
{
    return {kRequestSpectrum};
}

std::vector<std::uint8_t> setTriggerMode(std::uint16_t mode)
{
    std::vector<std::uint8_t> out{kSetTriggerMode};
    putLe16(out, mode);
    return out;
}

Expected<Status> parseStatus(std::span<const std::uint8_t> reply)
{
    if (reply.size() != kStatusReplyBytes) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB2000+ status reply has {} bytes, expected {}",
                                     reply.size(), kStatusReplyBytes));
    }
    Status s;
    s.pixels = le16(reply, 0);
    s.integrationTimeUs = le32(reply, 2);
    s.lampEnabled = reply[6] != 0;
    s.triggerMode = reply[7];
    s.packetsPerSpectrum = reply[9];
    s.highSpeed = reply[14] == 0x80;
    return s;
}

Expected<std::span<const std::uint8_t>> slotData(std::span<const std::uint8_t> reply,
                                                 std::uint8_t slot)
{
    if (reply.size() != kSlotReplyBytes || reply[0] != kQuerySlot || reply[1] != slot) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB2000+ EEPROM slot {} reply is malformed ({} bytes, echo "
                                     "{:02x} {:02x}); unplug and replug the spectrometer",
                                     slot, reply.size(), reply.empty() ? 0 : reply[0],
                                     reply.size() < 2 ? 0 : reply[1]));
    }
    return reply.subspan(2);
}

std::string slotText(std::span<const std::uint8_t> data)
{
    std::string s;
    for (const std::uint8_t c : data) {
        if (c == 0) {
            break;
        }
        s.push_back(static_cast<char>(c));
    }
    const auto first = s.find_first_not_of(" \t\r\n");
    if (first == std::string::npos) {
        return {};
    }
    const auto last = s.find_last_not_of(" \t\r\n");
    return s.substr(first, last - first + 1);
}

Expected<double> slotNumber(std::span<const std::uint8_t> data, std::uint8_t slot)
{
    const std::string text = slotText(data);
    double value = 0.0;
    // std::from_chars never consults the locale: "3.5e-06" parses the same under de_DE.
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc{} || end != text.data() + text.size() ||
        !std::isfinite(value)) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB2000+ EEPROM slot {} holds '{}', not a number; the "
                                     "device's calibration is damaged: re-flash it with Ocean "
                                     "Optics' tools",
                                     slot, text));
    }
    return value;
}

std::uint16_t slotSaturation(std::span<const std::uint8_t> data)
{
    if (data.size() < 6) {
        return kFullScale;
    }
    const std::uint16_t level = le16(data, 4);
    return level == 0 ? kFullScale : level;
}

Expected<std::vector<std::uint16_t>> parseSpectrum(std::span<const std::uint8_t> bytes)
{
    if (bytes.size() != kSpectrumBytes) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB2000+ spectrum transfer has {} bytes, expected {}",
                                     bytes.size(), kSpectrumBytes));
    }
    if (bytes.back() != kSyncByte) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("USB2000+ spectrum ends in 0x{:02x}, not the sync byte 0x69: "
                                     "lost synchronisation",
                                     bytes.back()));
    }
    std::vector<std::uint16_t> counts(kPixels);
    for (int p = 0; p < kPixels; ++p) {
        counts[static_cast<std::size_t>(p)] = le16(bytes, 2 * static_cast<std::size_t>(p));
    }
    return counts;
}

} // namespace replica::hal::spectrometer::usb2000
