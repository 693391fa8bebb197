// A USB HID report-descriptor parser (HID 1.11 section 6.2.2): short and long items, the global
// state with Push/Pop, local usages and usage ranges, collections, report IDs, sizes and counts,
// logical ranges, unit and unit exponent. It flattens every Input, Output and Feature main item
// into one field per reported value, with its bit position in the report, so that a driver can
// find the values it wants by usage and read them from raw report bytes. Devices whose descriptor
// is malformed are refused with the byte offset of the fault.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::hal::hid {

// What a descriptor may ask for (docs/limits.md). Past one, parsing fails with the limit and the
// value, and the device is not used. Together they cap a parsed descriptor at a few MiB:
// kMaxFields fields, each with at most kMaxCollectionDepth enclosing usages.
constexpr std::size_t kMaxDescriptorBytes = 4096; // the kernel's HID_MAX_DESCRIPTOR_SIZE
constexpr std::size_t kMaxCollectionDepth = 32;
constexpr std::size_t kMaxCollections = 1024;
constexpr std::size_t kMaxFields = 12288;       // the kernel's HID_MAX_USAGES
constexpr std::uint32_t kMaxReportCount = 4096; // values in one main item
constexpr std::uint32_t kMaxReportBytes = 8192; // data bytes of one report (hidraw buffers 16 KiB)
constexpr std::size_t kMaxPushDepth = 16;

enum class ReportType { Input, Output, Feature };

const char* toString(ReportType t);

// A usage: page in the high 16 bits, id in the low 16 (HID's "extended usage").
constexpr std::uint32_t usage(std::uint16_t page, std::uint16_t id)
{
    return (static_cast<std::uint32_t>(page) << 16) | id;
}

// A 4-bit two's-complement nibble (the low four bits of v) as -8..7.
constexpr int signedNibble(std::uint32_t v)
{
    const int n = static_cast<int>(v & 0xF);
    return n >= 8 ? n - 16 : n;
}

// HID unit systems (the low nibble of Unit).
enum class UnitSystem { None, SiLinear, SiRotation, EnglishLinear, EnglishRotation, Vendor };

struct HidUnit {
    std::uint32_t raw = 0; // as in the descriptor
    int exponent = 0;      // Unit Exponent, power of ten: -8..7 (the parser refuses others)

    UnitSystem system() const;
    // The power of one base dimension (nibble 1 length, 2 mass, 3 time, 4 temperature, 5 current,
    // 6 luminous intensity), as a signed nibble.
    int power(int nibble) const;
    // Metres per logical unit for a pure length (cm or inch, times 10^exponent); 0 otherwise.
    double metresPerUnit() const;
    // Seconds per logical unit for a pure time; 0 otherwise.
    double secondsPerUnit() const;
};

// One reported value: a single element of a Variable main item (arrays and constants are kept
// as padding: they take space in the report but have no usage).
struct HidField {
    ReportType type = ReportType::Input;
    std::uint8_t reportId = 0;   // 0: the device does not number its reports
    std::uint32_t bitOffset = 0; // from the start of the report's data (after the ID byte)
    std::uint32_t bitSize = 0;   // 1..64
    std::uint32_t usage = 0;     // page << 16 | id; 0 for padding
    bool constant = false;       // Constant or Array item: padding for our purposes
    bool relative = false;       // Relative (rather than Absolute) data
    bool nullState = false;      // values outside the logical range mean "no value"
    std::int64_t logicalMin = 0; // signed when logicalMin < 0
    std::int64_t logicalMax = 0;
    // Physical Minimum and Maximum: both 0 means the physical value is the logical one.
    std::int64_t physicalMin = 0;
    std::int64_t physicalMax = 0;
    HidUnit unit;
    std::size_t itemAt = 0; // byte offset of the main item that declared it (for errors)
    // Usages of the enclosing collections, outermost first.
    std::vector<std::uint32_t> collections;

    bool isSigned() const { return logicalMin < 0; }
    bool within(std::uint32_t collectionUsage) const;
};

struct HidCollection {
    std::uint32_t usage = 0;
    std::uint8_t type = 0; // 0 physical, 1 application, 2 logical, ...
    int depth = 0;
};

struct ReportDescriptor {
    std::vector<HidField> fields;
    std::vector<HidCollection> collections; // in descriptor order
    bool numberedReports = false;           // any Report ID item: every report starts with its ID
    // Data bits of each report (without the ID byte), keyed by (type, id).
    std::map<std::pair<ReportType, std::uint8_t>, std::uint32_t> reportBits;

    // Bytes a report of this type and ID occupies on the wire, with the ID byte when numbered.
    std::size_t reportBytes(ReportType type, std::uint8_t id) const;
    const HidField*
    find(ReportType type, std::uint32_t usage, std::uint32_t withinCollection = 0) const;
};

// Parses a report descriptor; errors name the byte offset and what is wrong with it.
Expected<ReportDescriptor> parseReportDescriptor(std::span<const std::uint8_t> bytes);

// Reads a field's raw value from a report's data bytes (without the ID byte); nullopt when the
// report is too short to hold it. Sign-extended for signed fields.
std::optional<std::int64_t> extractField(const HidField& f, std::span<const std::uint8_t> data);

// Writes a field's value into a report's data bytes (which must be long enough).
void insertField(const HidField& f, std::span<std::uint8_t> data, std::int64_t value);

// A logical value in the field's physical range (HID 1.11 6.2.2.7): (logical - LogMin) *
// (PhysMax - PhysMin) / (LogMax - LogMin) + PhysMin, in the field's unit times 10^exponent; the
// logical value itself when the physical range is 0..0. Nullopt when a physical range is given
// over an empty logical range (LogMin == LogMax): nothing can be scaled then.
std::optional<double> physicalValue(const HidField& f, std::int64_t logical);

// The field 'first' joined with the fields right after it that repeat its usage, as one
// little-endian integer of up to 64 bits: a descriptor that declares one usage over several
// 8-bit fields (Microsoft's reference eye tracker: Sensor Timestamp, Report Size 8, Report Count
// 8, a uint64 microsecond counter) means one value in those bytes, not eight values of which the
// first would do. The joined field is unsigned and has no logical or physical range (those of a
// byte say nothing about the whole). 'first' must be one of d.fields; it is returned as it is
// when no byte field of its usage follows it.
HidField joinedBytes(const ReportDescriptor& d, const HidField& first);

} // namespace replica::hal::hid
