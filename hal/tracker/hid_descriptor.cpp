// HID report-descriptor parsing (HID 1.11, 6.2.2 "Report Descriptor").
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <hal/tracker/hid_descriptor.h>

namespace replica::hal::hid {
namespace {

constexpr std::uint32_t kMaxReportBits = 8192 * 8; // hidraw's HID_MAX_BUFFER_SIZE is 16 KiB
constexpr std::uint32_t kMaxReportCount = 4096;
constexpr std::size_t kMaxPushDepth = 16;
constexpr std::size_t kMaxUsageRange = 65536;

// Item types and tags (HID 1.11, 6.2.2.4 - 6.2.2.8).
enum : std::uint8_t { kMain = 0, kGlobal = 1, kLocal = 2, kReserved = 3 };
enum : std::uint8_t {
    kInput = 0x8,
    kOutput = 0x9,
    kCollection = 0xA,
    kFeature = 0xB,
    kEndCollection = 0xC,
};
enum : std::uint8_t {
    kUsagePage = 0x0,
    kLogicalMin = 0x1,
    kLogicalMax = 0x2,
    kPhysicalMin = 0x3,
    kPhysicalMax = 0x4,
    kUnitExponent = 0x5,
    kUnit = 0x6,
    kReportSize = 0x7,
    kReportId = 0x8,
    kReportCount = 0x9,
    kPush = 0xA,
    kPop = 0xB,
};
enum : std::uint8_t { kUsage = 0x0, kUsageMin = 0x1, kUsageMax = 0x2 };

struct ItemValue {
    std::uint32_t raw = 0;
    int size = 0; // data bytes: 0, 1, 2 or 4
    std::int64_t asSigned() const
    {
        switch (size) {
        case 1:
            return static_cast<std::int8_t>(raw);
        case 2:
            return static_cast<std::int16_t>(raw);
        case 4:
            return static_cast<std::int32_t>(raw);
        default:
            return 0;
        }
    }
};

struct GlobalState {
    std::uint16_t usagePage = 0;
    ItemValue logicalMin;
    ItemValue logicalMax;
    HidUnit unit;
    std::uint32_t reportSize = 0;
    std::uint32_t reportCount = 0;
    std::uint8_t reportId = 0;
};

struct LocalUsage {
    std::uint32_t value = 0;
    int size = 0; // a 4-byte usage carries its own page
};

std::uint32_t resolve(const LocalUsage& u, std::uint16_t page)
{
    return u.size == 4 ? u.value : usage(page, static_cast<std::uint16_t>(u.value & 0xFFFF));
}

// Logical limits as the descriptor means them: signed two's complement in the item's size, except
// that a maximum which reads below a non-negative minimum was meant unsigned (a common way to
// write 0..255 in one byte, which Linux and Windows accept).
std::pair<std::int64_t, std::int64_t> logicalRange(const GlobalState& g)
{
    const std::int64_t lo = g.logicalMin.asSigned();
    std::int64_t hi = g.logicalMax.asSigned();
    if (lo >= 0 && hi < lo) {
        hi = static_cast<std::int64_t>(g.logicalMax.raw);
    }
    return {lo, hi};
}

int signedNibble(std::uint32_t v)
{
    const int n = static_cast<int>(v & 0xF);
    return n >= 8 ? n - 16 : n;
}

Error errorAt(std::size_t offset, const std::string& what)
{
    return Error{ErrorCode::Corrupt,
                 fmt::format("HID report descriptor byte {}: {}", offset, what)};
}

} // namespace

const char* toString(ReportType t)
{
    switch (t) {
    case ReportType::Input:
        return "input";
    case ReportType::Output:
        return "output";
    case ReportType::Feature:
        return "feature";
    }
    return "unknown";
}

UnitSystem HidUnit::system() const
{
    switch (raw & 0xF) {
    case 0:
        return UnitSystem::None;
    case 1:
        return UnitSystem::SiLinear;
    case 2:
        return UnitSystem::SiRotation;
    case 3:
        return UnitSystem::EnglishLinear;
    case 4:
        return UnitSystem::EnglishRotation;
    default:
        return UnitSystem::Vendor;
    }
}

int HidUnit::power(int nibble) const
{
    return signedNibble(raw >> (4 * nibble));
}

double HidUnit::metresPerUnit() const
{
    // Length to the first power and nothing else.
    if ((raw & 0xFFFFFFF0u) != 0x10u) {
        return 0.0;
    }
    const double base = system() == UnitSystem::SiLinear        ? 0.01   // centimetre
                        : system() == UnitSystem::EnglishLinear ? 0.0254 // inch
                                                                : 0.0;
    return base * std::pow(10.0, exponent);
}

double HidUnit::secondsPerUnit() const
{
    if ((raw & 0xFFFFF0F0u) != 0x1000u || system() == UnitSystem::None ||
        system() == UnitSystem::Vendor) {
        return 0.0;
    }
    return std::pow(10.0, exponent); // the second in every system
}

bool HidField::within(std::uint32_t collectionUsage) const
{
    return std::find(collections.begin(), collections.end(), collectionUsage) != collections.end();
}

std::size_t ReportDescriptor::reportBytes(ReportType type, std::uint8_t id) const
{
    const auto it = reportBits.find({type, id});
    const std::size_t bits = it == reportBits.end() ? 0 : it->second;
    return (bits + 7) / 8 + (numberedReports ? 1 : 0);
}

const HidField*
ReportDescriptor::find(ReportType type, std::uint32_t u, std::uint32_t withinCollection) const
{
    for (const auto& f : fields) {
        if (f.type == type && f.usage == u && !f.constant &&
            (withinCollection == 0 || f.within(withinCollection))) {
            return &f;
        }
    }
    return nullptr;
}

Expected<ReportDescriptor> parseReportDescriptor(std::span<const std::uint8_t> bytes)
{
    if (bytes.empty()) {
        return makeError(ErrorCode::Corrupt, "HID report descriptor is empty");
    }
    ReportDescriptor d;
    GlobalState g;
    std::vector<GlobalState> stack;
    std::vector<LocalUsage> usages;
    LocalUsage usageMin;
    LocalUsage usageMax;
    bool haveMin = false;
    bool haveMax = false;
    std::vector<HidCollection> open;

    std::size_t pos = 0;
    while (pos < bytes.size()) {
        const std::size_t at = pos;
        const std::uint8_t prefix = bytes[pos++];
        if (prefix == 0xFE) { // long item: size, tag, data; no long items are defined, skip
            if (pos + 2 > bytes.size()) {
                return tl::unexpected(errorAt(at, "long item cut short"));
            }
            const std::size_t n = bytes[pos];
            pos += 2;
            if (pos + n > bytes.size()) {
                return tl::unexpected(
                        errorAt(at, fmt::format("long item needs {} data bytes, only {} left", n,
                                                bytes.size() - pos)));
            }
            pos += n;
            continue;
        }
        const int size = (prefix & 3) == 3 ? 4 : (prefix & 3);
        const std::uint8_t type = (prefix >> 2) & 3;
        const std::uint8_t tag = prefix >> 4;
        if (pos + static_cast<std::size_t>(size) > bytes.size()) {
            return tl::unexpected(
                    errorAt(at, fmt::format("item 0x{:02x} needs {} data bytes, only {} left",
                                            prefix, size, bytes.size() - pos)));
        }
        ItemValue v;
        v.size = size;
        for (int i = 0; i < size; ++i) {
            v.raw |= static_cast<std::uint32_t>(bytes[pos + static_cast<std::size_t>(i)])
                     << (8 * i);
        }
        pos += static_cast<std::size_t>(size);

        if (type == kReserved) {
            return tl::unexpected(
                    errorAt(at, fmt::format("reserved item type (0x{:02x})", prefix)));
        }
        if (type == kGlobal) {
            switch (tag) {
            case kUsagePage:
                g.usagePage = static_cast<std::uint16_t>(v.raw);
                break;
            case kLogicalMin:
                g.logicalMin = v;
                break;
            case kLogicalMax:
                g.logicalMax = v;
                break;
            case kPhysicalMin:
            case kPhysicalMax:
                break; // physical ranges only rescale; the trackers' units come with logical values
            case kUnitExponent:
                // HID 1.11 codes it as a signed nibble; some descriptors write a signed byte.
                g.unit.exponent = (size == 1 && v.raw <= 0xF) ? signedNibble(v.raw)
                                                              : static_cast<int>(v.asSigned());
                break;
            case kUnit:
                g.unit.raw = v.raw;
                break;
            case kReportSize:
                g.reportSize = v.raw;
                break;
            case kReportId:
                if (v.raw == 0 || v.raw > 255) {
                    return tl::unexpected(
                            errorAt(at, fmt::format("report ID {} (must be 1..255)", v.raw)));
                }
                g.reportId = static_cast<std::uint8_t>(v.raw);
                d.numberedReports = true;
                break;
            case kReportCount:
                g.reportCount = v.raw;
                break;
            case kPush:
                if (stack.size() >= kMaxPushDepth) {
                    return tl::unexpected(errorAt(at, "Push nested too deep"));
                }
                stack.push_back(g);
                break;
            case kPop:
                if (stack.empty()) {
                    return tl::unexpected(errorAt(at, "Pop without a Push"));
                }
                g = stack.back();
                stack.pop_back();
                break;
            default:
                return tl::unexpected(
                        errorAt(at, fmt::format("reserved global item tag 0x{:x}", tag)));
            }
            continue;
        }
        if (type == kLocal) {
            switch (tag) {
            case kUsage:
                usages.push_back({v.raw, size});
                break;
            case kUsageMin:
                usageMin = LocalUsage{v.raw, size};
                haveMin = true;
                break;
            case kUsageMax:
                usageMax = LocalUsage{v.raw, size};
                haveMax = true;
                break;
            default:
                break; // designators, strings, delimiters: not needed here
            }
            continue;
        }
        // Main items.
        std::vector<std::uint32_t> resolved;
        for (const auto& u : usages) {
            resolved.push_back(resolve(u, g.usagePage));
        }
        if (haveMin || haveMax) {
            if (!haveMin || !haveMax) {
                return tl::unexpected(errorAt(at, "Usage Minimum without Usage Maximum (or the "
                                                  "other way round)"));
            }
            const std::uint32_t lo = resolve(usageMin, g.usagePage);
            const std::uint32_t hi = resolve(usageMax, g.usagePage);
            if (hi < lo || hi - lo >= kMaxUsageRange) {
                return tl::unexpected(
                        errorAt(at, fmt::format("usage range 0x{:x}..0x{:x} is empty or too large",
                                                lo, hi)));
            }
            for (std::uint32_t u = lo; u <= hi; ++u) {
                resolved.push_back(u);
            }
        }
        usages.clear();
        haveMin = false;
        haveMax = false;

        switch (tag) {
        case kCollection: {
            HidCollection c;
            c.usage = resolved.empty() ? 0 : resolved.front();
            c.type = static_cast<std::uint8_t>(v.raw);
            c.depth = static_cast<int>(open.size());
            open.push_back(c);
            d.collections.push_back(c);
            break;
        }
        case kEndCollection:
            if (open.empty()) {
                return tl::unexpected(errorAt(at, "End Collection without a Collection"));
            }
            open.pop_back();
            break;
        case kInput:
        case kOutput:
        case kFeature: {
            const ReportType rt = tag == kInput    ? ReportType::Input
                                  : tag == kOutput ? ReportType::Output
                                                   : ReportType::Feature;
            if (g.reportSize == 0 || g.reportSize > 64) {
                return tl::unexpected(
                        errorAt(at, fmt::format("{} item with Report Size {} (must be 1..64)",
                                                toString(rt), g.reportSize)));
            }
            if (g.reportCount > kMaxReportCount) {
                return tl::unexpected(
                        errorAt(at, fmt::format("Report Count {} is implausible", g.reportCount)));
            }
            auto& bits = d.reportBits[{rt, g.reportId}];
            const bool constant = (v.raw & 0x01) != 0;
            const bool variable = (v.raw & 0x02) != 0;
            // Not a structured binding: clang before 16 cannot capture one in the lambda below
            // (the libFuzzer build, tests/fuzz/run_fuzz.sh).
            const auto logical = logicalRange(g);
            std::vector<std::uint32_t> path;
            for (const auto& c : open) {
                path.push_back(c.usage);
            }
            auto make = [&](std::uint32_t u, std::uint32_t bitSize) {
                HidField f;
                f.type = rt;
                f.reportId = g.reportId;
                f.bitOffset = bits;
                f.bitSize = bitSize;
                f.usage = u;
                f.constant = constant || !variable || u == 0;
                f.relative = (v.raw & 0x04) != 0;
                f.nullState = (v.raw & 0x40) != 0;
                f.logicalMin = logical.first;
                f.logicalMax = logical.second;
                f.unit = g.unit;
                f.collections = path;
                return f;
            };
            if (constant || !variable) {
                // Padding or an array of selectors: space in the report, no values for us.
                if (g.reportCount > 0) {
                    d.fields.push_back(make(0, g.reportSize * g.reportCount));
                }
            } else {
                for (std::uint32_t i = 0; i < g.reportCount; ++i) {
                    const std::uint32_t u =
                            resolved.empty()
                                    ? 0
                                    : resolved[std::min<std::size_t>(i, resolved.size() - 1)];
                    d.fields.push_back(make(u, g.reportSize));
                    d.fields.back().bitOffset = bits + i * g.reportSize;
                }
            }
            bits += g.reportSize * g.reportCount;
            if (bits > kMaxReportBits) {
                return tl::unexpected(
                        errorAt(at, fmt::format("{} report {} grows beyond {} bytes", toString(rt),
                                                g.reportId, kMaxReportBits / 8)));
            }
            break;
        }
        default:
            return tl::unexpected(errorAt(at, fmt::format("reserved main item tag 0x{:x}", tag)));
        }
    }
    if (!open.empty()) {
        return tl::unexpected(
                errorAt(bytes.size(), fmt::format("{} collection(s) never closed", open.size())));
    }
    if (d.numberedReports) {
        for (const auto& f : d.fields) {
            if (f.reportId == 0) {
                return makeError(ErrorCode::Corrupt,
                                 "HID report descriptor: some reports have IDs and some have none; "
                                 "a device must number all its reports or none");
            }
        }
    }
    return d;
}

std::optional<std::int64_t> extractField(const HidField& f, std::span<const std::uint8_t> data)
{
    if (f.bitSize == 0 || f.bitSize > 64 || (f.bitOffset + f.bitSize + 7) / 8 > data.size()) {
        return std::nullopt;
    }
    std::uint64_t v = 0;
    for (std::uint32_t k = 0; k < f.bitSize; ++k) {
        const std::uint32_t bit = f.bitOffset + k;
        if ((data[bit / 8] >> (bit % 8)) & 1u) {
            v |= std::uint64_t{1} << k;
        }
    }
    if (f.isSigned() && f.bitSize < 64 && (v >> (f.bitSize - 1)) & 1u) {
        v |= ~std::uint64_t{0} << f.bitSize;
    }
    return static_cast<std::int64_t>(v);
}

void insertField(const HidField& f, std::span<std::uint8_t> data, std::int64_t value)
{
    const auto v = static_cast<std::uint64_t>(value);
    for (std::uint32_t k = 0; k < f.bitSize && k < 64; ++k) {
        const std::uint32_t bit = f.bitOffset + k;
        if (bit / 8 >= data.size()) {
            return;
        }
        const auto mask = static_cast<std::uint8_t>(1u << (bit % 8));
        if ((v >> k) & 1u) {
            data[bit / 8] = static_cast<std::uint8_t>(data[bit / 8] | mask);
        } else {
            data[bit / 8] = static_cast<std::uint8_t>(data[bit / 8] & ~mask);
        }
    }
}

} // namespace replica::hal::hid
