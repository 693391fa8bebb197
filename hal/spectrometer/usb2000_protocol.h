// The Ocean Optics USB2000+ command set (OOI protocol) as bytes: what the driver sends and how it
// reads the replies. Pure functions, no I/O; see docs/hardware.md for the sources.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::hal::spectrometer::usb2000 {

constexpr std::uint16_t kVendorId = 0x2457;
constexpr std::uint16_t kProductId = 0x101E;

constexpr std::uint8_t kEpCommandOut = 0x01;
constexpr std::uint8_t kEpReplyIn = 0x81;
constexpr std::uint8_t kEpSpectrumIn = 0x82;

constexpr int kPixels = 2048;
constexpr std::size_t kSpectrumBytes = 2 * kPixels + 1; // pixels, then one sync byte
constexpr std::uint8_t kSyncByte = 0x69;
constexpr int kDarkPixelFirst = 6; // electrically dark (masked) pixels, inclusive
constexpr int kDarkPixelLast = 20;
constexpr std::size_t kSlotReplyBytes = 17;
constexpr std::size_t kStatusReplyBytes = 16;
constexpr std::uint16_t kFullScale = 65535;

// Integration time limits Replica enforces (the device silently ignores out-of-range values).
constexpr std::uint32_t kMinIntegrationUs = 1'000;
constexpr std::uint32_t kMaxIntegrationUs = 65'000'000;
constexpr std::uint32_t kIntegrationStepUs = 1'000;

enum Opcode : std::uint8_t {
    kInitialise = 0x01,
    kSetIntegrationTime = 0x02,
    kQuerySlot = 0x05,
    kRequestSpectrum = 0x09,
    kSetTriggerMode = 0x0A,
    kReadRegister = 0x6B,
    kQueryStatus = 0xFE,
};

// EEPROM slots the driver reads.
enum Slot : std::uint8_t {
    kSlotSerial = 0,
    kSlotWavelength0 = 1,   // 1..4: c0..c3
    kSlotNonlinearity0 = 6, // 6..13: k0..k7
    kSlotNonlinearityOrder = 14,
    kSlotSaturation = 17,
};

std::vector<std::uint8_t> initialise();
// Clamped to [kMinIntegrationUs, kMaxIntegrationUs] and rounded to the 1 ms step.
std::uint32_t clampIntegrationUs(std::uint64_t requestedUs);
std::vector<std::uint8_t> setIntegrationTime(std::uint32_t us);
std::vector<std::uint8_t> querySlot(std::uint8_t slot);
std::vector<std::uint8_t> requestSpectrum();
std::vector<std::uint8_t> setTriggerMode(std::uint16_t mode);

struct Status {
    std::uint16_t pixels = 0;
    std::uint32_t integrationTimeUs = 0;
    bool lampEnabled = false;
    std::uint8_t triggerMode = 0;
    std::uint8_t packetsPerSpectrum = 0;
    bool highSpeed = false;
};

Expected<Status> parseStatus(std::span<const std::uint8_t> reply);

// The data bytes of a slot reply after checking its echo (05 <slot>).
Expected<std::span<const std::uint8_t>> slotData(std::span<const std::uint8_t> reply,
                                                 std::uint8_t slot);
// ASCII up to the first NUL, trimmed.
std::string slotText(std::span<const std::uint8_t> data);
// A C-locale floating-point number, whatever the process locale; fails naming the slot.
Expected<double> slotNumber(std::span<const std::uint8_t> data, std::uint8_t slot);
// Slot 17: binary u16 LE at data bytes 4-5; 0 (not programmed) means full scale.
std::uint16_t slotSaturation(std::span<const std::uint8_t> data);

// 2048 little-endian u16 counts from a 4097-byte transfer, after checking its sync byte.
Expected<std::vector<std::uint16_t>> parseSpectrum(std::span<const std::uint8_t> bytes);

} // namespace replica::hal::spectrometer::usb2000
