// HID report-descriptor parsing (HID 1.11, 6.2.2 "Report Descriptor").
#include <algorithm>

#include <fmt/format.h>

#include <hal/tracker/hid_descriptor.h>

namespace replica::hal::hid {
namespace {

constexpr std::uint32_t kMaxReportBits = kMaxReportBytes * 8;
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
    ItemValue physicalMin;
    ItemValue physicalMax;
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

// Limits as the descriptor means them (logical or physical): signed two's complement in the
// item's size, except that a maximum which reads below a non-negative minimum was meant unsigned
// (a common way to write 0..255 in one byte, which Linux and Windows accept). A minimum that is
// still above the maximum is a broken descriptor, which the users of the field refuse.
std::pair<std::int64_t, std::int64_t> rangeOf(const ItemValue& min, const ItemValue& max)
{
    const std::int64_t lo = min.asSigned();
    std::int64_t hi = max.asSigned();
    if (lo >= 0 && hi < lo) {
        hi = static_cast<std::int64_t>(max.raw);
    }
    return {lo, hi};
}

Error errorAt(std::size_t offset, const std::string& what)
{
    return Error{ErrorCode::Corrupt,
                 fmt::format("HID report descriptor byte {}: {}", offset, what)};
}

// One short item as read from the descriptor (long items are skipped by readItem).
struct Item {
    std::size_t at = 0; // byte offset of the prefix
    std::uint8_t prefix = 0;
    std::uint8_t type = 0;
    std::uint8_t tag = 0;
    ItemValue value;
    bool skip = false; // a long item: nothing to act on
};

// Reads the item at 'pos' and moves 'pos' past it.
Expected<Item> readItem(std::span<const std::uint8_t> bytes, std::size_t& pos)
{
    Item item;
    item.at = pos;
    item.prefix = bytes[pos++];
    if (item.prefix == 0xFE) { // long item: size, tag, data; no long items are defined, skip
        if (pos + 2 > bytes.size()) {
            return tl::unexpected(errorAt(item.at, "long item cut short"));
        }
        const std::size_t n = bytes[pos];
        pos += 2;
        if (pos + n > bytes.size()) {
            return tl::unexpected(
                    errorAt(item.at, fmt::format("long item needs {} data bytes, only {} left", n,
                                                 bytes.size() - pos)));
        }
        pos += n;
        item.skip = true;
        return item;
    }
    const int size = (item.prefix & 3) == 3 ? 4 : (item.prefix & 3);
    item.type = (item.prefix >> 2) & 3;
    item.tag = item.prefix >> 4;
    if (pos + static_cast<std::size_t>(size) > bytes.size()) {
        return tl::unexpected(
                errorAt(item.at, fmt::format("item 0x{:02x} needs {} data bytes, only {} left",
                                             item.prefix, size, bytes.size() - pos)));
    }
    item.value.size = size;
    for (int i = 0; i < size; ++i) {
        item.value.raw |= static_cast<std::uint32_t>(bytes[pos + static_cast<std::size_t>(i)])
                          << (8 * i);
    }
    pos += static_cast<std::size_t>(size);
    if (item.type == kReserved) {
        return tl::unexpected(
                errorAt(item.at, fmt::format("reserved item type (0x{:02x})", item.prefix)));
    }
    return item;
}

// The usages a main item gives its values: the Usage items in order, then a Usage Minimum..Maximum
// range, the last one repeated for any further value. The range is not spelled out (a 4 KiB
// descriptor could otherwise ask for millions of them).
struct MainUsages {
    std::vector<std::uint32_t> list;
    std::uint32_t rangeLo = 0;
    std::uint32_t rangeCount = 0;

    bool empty() const { return list.empty() && rangeCount == 0; }
    std::uint32_t at(std::uint32_t i) const
    {
        if (i < list.size()) {
            return list[i];
        }
        if (rangeCount == 0) {
            return list.back();
        }
        const auto k = static_cast<std::uint32_t>(i - list.size());
        return rangeLo + std::min(k, rangeCount - 1);
    }
};

class DescriptorParser
{
public:
    Expected<ReportDescriptor> run(std::span<const std::uint8_t> bytes);

private:
    Expected<void> global(const Item& item);
    Expected<void> unitExponent(const Item& item);
    void local(const Item& item);
    Expected<MainUsages> takeUsages(const Item& item);
    Expected<void> main(const Item& item);
    Expected<void> collection(const Item& item, const MainUsages& usages);
    Expected<void> data(const Item& item, const MainUsages& usages);
    Expected<void> finish(std::size_t end);

    ReportDescriptor d_;
    GlobalState g_;
    std::vector<GlobalState> stack_;
    std::vector<LocalUsage> usages_;
    LocalUsage usageMin_;
    LocalUsage usageMax_;
    bool haveMin_ = false;
    bool haveMax_ = false;
    std::vector<HidCollection> open_;
};

Expected<ReportDescriptor> DescriptorParser::run(std::span<const std::uint8_t> bytes)
{
    if (bytes.empty()) {
        return makeError(ErrorCode::Corrupt, "HID report descriptor is empty");
    }
    if (bytes.size() > kMaxDescriptorBytes) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("HID report descriptor of {} bytes, more than the {} a device "
                                     "may have (the kernel's HID_MAX_DESCRIPTOR_SIZE)",
                                     bytes.size(), kMaxDescriptorBytes));
    }
    std::size_t pos = 0;
    while (pos < bytes.size()) {
        auto item = readItem(bytes, pos);
        if (!item) {
            return tl::unexpected(item.error());
        }
        Expected<void> ok;
        if (item->skip) {
            continue;
        }
        if (item->type == kGlobal) {
            ok = global(*item);
        } else if (item->type == kLocal) {
            local(*item);
        } else {
            ok = main(*item);
        }
        if (!ok) {
            return tl::unexpected(ok.error());
        }
    }
    if (auto ok = finish(bytes.size()); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::move(d_);
}

Expected<void> DescriptorParser::global(const Item& item)
{
    const ItemValue& v = item.value;
    switch (item.tag) {
    case kUsagePage:
        g_.usagePage = static_cast<std::uint16_t>(v.raw);
        break;
    case kLogicalMin:
        g_.logicalMin = v;
        break;
    case kLogicalMax:
        g_.logicalMax = v;
        break;
    case kPhysicalMin:
        g_.physicalMin = v;
        break;
    case kPhysicalMax:
        g_.physicalMax = v;
        break;
    case kUnitExponent:
        return unitExponent(item);
    case kUnit:
        g_.unit.raw = v.raw;
        break;
    case kReportSize:
        g_.reportSize = v.raw;
        break;
    case kReportId:
        if (v.raw == 0 || v.raw > 255) {
            return tl::unexpected(
                    errorAt(item.at, fmt::format("report ID {} (must be 1..255)", v.raw)));
        }
        g_.reportId = static_cast<std::uint8_t>(v.raw);
        d_.numberedReports = true;
        break;
    case kReportCount:
        g_.reportCount = v.raw;
        break;
    case kPush:
        if (stack_.size() >= kMaxPushDepth) {
            return tl::unexpected(errorAt(
                    item.at, fmt::format("Push nested deeper than {} levels", kMaxPushDepth)));
        }
        stack_.push_back(g_);
        break;
    case kPop:
        if (stack_.empty()) {
            return tl::unexpected(errorAt(item.at, "Pop without a Push"));
        }
        g_ = stack_.back();
        stack_.pop_back();
        break;
    default:
        return tl::unexpected(
                errorAt(item.at, fmt::format("reserved global item tag 0x{:x}", item.tag)));
    }
    return {};
}

// HID 1.11 codes the Unit Exponent as a 4-bit two's-complement nibble whatever the item's size
// (`56 0D 00` is -3, not 13); some descriptors write a signed byte instead (0xFD). As Linux's
// hid-core reads it: a value with no bits above the low four is a nibble, any other a signed
// value. What is then outside -8..7 is no unit a device can mean (400 made a position of inf m,
// 127 one of 5e129 m, -400 a unit of 0 m): the descriptor is refused.
Expected<void> DescriptorParser::unitExponent(const Item& item)
{
    const ItemValue& v = item.value;
    const std::int64_t e = (v.raw >> 4) == 0 ? signedNibble(v.raw) : v.asSigned();
    if (e < -8 || e > 7) {
        return tl::unexpected(errorAt(
                item.at, fmt::format("Unit Exponent {} (0x{:x} in {} byte{}) is outside -8..7", e,
                                     v.raw, v.size, v.size == 1 ? "" : "s")));
    }
    g_.unit.exponent = static_cast<int>(e);
    return {};
}

void DescriptorParser::local(const Item& item)
{
    const LocalUsage u{item.value.raw, item.value.size};
    switch (item.tag) {
    case kUsage:
        usages_.push_back(u); // at most one per descriptor byte: bounded by its length
        break;
    case kUsageMin:
        usageMin_ = u;
        haveMin_ = true;
        break;
    case kUsageMax:
        usageMax_ = u;
        haveMax_ = true;
        break;
    default:
        break; // designators, strings, delimiters: not needed here
    }
}

// The local usages resolved against the current page, cleared for the next main item.
Expected<MainUsages> DescriptorParser::takeUsages(const Item& item)
{
    MainUsages m;
    for (const auto& u : usages_) {
        m.list.push_back(resolve(u, g_.usagePage));
    }
    const bool range = haveMin_ || haveMax_;
    const bool bothEnds = haveMin_ && haveMax_;
    usages_.clear();
    haveMin_ = false;
    haveMax_ = false;
    if (!range) {
        return m;
    }
    if (!bothEnds) {
        return tl::unexpected(errorAt(item.at, "Usage Minimum without Usage Maximum (or the "
                                               "other way round)"));
    }
    const std::uint32_t lo = resolve(usageMin_, g_.usagePage);
    const std::uint32_t hi = resolve(usageMax_, g_.usagePage);
    if (hi < lo || hi - lo >= kMaxUsageRange) {
        return tl::unexpected(errorAt(
                item.at, fmt::format("usage range 0x{:x}..0x{:x} is empty or too large", lo, hi)));
    }
    m.rangeLo = lo;
    m.rangeCount = hi - lo + 1;
    return m;
}

Expected<void> DescriptorParser::main(const Item& item)
{
    auto usages = takeUsages(item);
    if (!usages) {
        return tl::unexpected(usages.error());
    }
    switch (item.tag) {
    case kCollection:
        return collection(item, *usages);
    case kEndCollection:
        if (open_.empty()) {
            return tl::unexpected(errorAt(item.at, "End Collection without a Collection"));
        }
        open_.pop_back();
        return {};
    case kInput:
    case kOutput:
    case kFeature:
        return data(item, *usages);
    default:
        return tl::unexpected(
                errorAt(item.at, fmt::format("reserved main item tag 0x{:x}", item.tag)));
    }
}

Expected<void> DescriptorParser::collection(const Item& item, const MainUsages& usages)
{
    if (open_.size() >= kMaxCollectionDepth) {
        return tl::unexpected(
                errorAt(item.at, fmt::format("collections nested deeper than {} levels (the limit)",
                                             kMaxCollectionDepth)));
    }
    if (d_.collections.size() >= kMaxCollections) {
        return tl::unexpected(errorAt(
                item.at, fmt::format("more than {} collections (the limit)", kMaxCollections)));
    }
    HidCollection c;
    c.usage = usages.empty() ? 0 : usages.at(0);
    c.type = static_cast<std::uint8_t>(item.value.raw);
    c.depth = static_cast<int>(open_.size());
    open_.push_back(c);
    d_.collections.push_back(c);
    return {};
}

// An Input, Output or Feature item: its values as fields at their bit positions in the report.
Expected<void> DescriptorParser::data(const Item& item, const MainUsages& usages)
{
    const ItemValue& v = item.value;
    const ReportType rt = item.tag == kInput    ? ReportType::Input
                          : item.tag == kOutput ? ReportType::Output
                                                : ReportType::Feature;
    if (g_.reportSize == 0 || g_.reportSize > 64) {
        return tl::unexpected(errorAt(item.at, fmt::format("{} item with Report Size {} (must be "
                                                           "1..64)",
                                                           toString(rt), g_.reportSize)));
    }
    if (g_.reportCount > kMaxReportCount) {
        return tl::unexpected(errorAt(item.at, fmt::format("Report Count {} is more than the {} "
                                                           "an item may have",
                                                           g_.reportCount, kMaxReportCount)));
    }
    auto& bits = d_.reportBits[{rt, g_.reportId}];
    // Checked before any field is made: the report's size bounds the fields of one report, and
    // kMaxFields all of them together (61 reports of 4,096 one-bit values would be 4 million).
    if (bits + g_.reportSize * g_.reportCount > kMaxReportBits) {
        return tl::unexpected(
                errorAt(item.at, fmt::format("{} report {} grows beyond {} bytes", toString(rt),
                                             g_.reportId, kMaxReportBits / 8)));
    }
    const bool constant = (v.raw & 0x01) != 0;
    const bool variable = (v.raw & 0x02) != 0;
    const std::uint32_t count =
            constant || !variable ? (g_.reportCount > 0 ? 1 : 0) : g_.reportCount;
    if (d_.fields.size() + count > kMaxFields) {
        return tl::unexpected(errorAt(
                item.at, fmt::format("more than {} fields in all (the limit)", kMaxFields)));
    }
    const auto logical = rangeOf(g_.logicalMin, g_.logicalMax);
    const auto physical = rangeOf(g_.physicalMin, g_.physicalMax);
    std::vector<std::uint32_t> path;
    for (const auto& c : open_) {
        path.push_back(c.usage);
    }
    for (std::uint32_t i = 0; i < count; ++i) {
        HidField f;
        f.type = rt;
        f.reportId = g_.reportId;
        f.bitOffset = bits + i * g_.reportSize;
        // Padding or an array of selectors: space in the report, no values for us.
        const bool padding = constant || !variable;
        f.bitSize = padding ? g_.reportSize * g_.reportCount : g_.reportSize;
        f.usage = padding || usages.empty() ? 0 : usages.at(i);
        f.constant = padding || f.usage == 0;
        f.relative = (v.raw & 0x04) != 0;
        f.nullState = (v.raw & 0x40) != 0;
        f.logicalMin = logical.first;
        f.logicalMax = logical.second;
        f.physicalMin = physical.first;
        f.physicalMax = physical.second;
        f.unit = g_.unit;
        f.itemAt = item.at;
        f.collections = path;
        d_.fields.push_back(std::move(f));
    }
    bits += g_.reportSize * g_.reportCount;
    return {};
}

Expected<void> DescriptorParser::finish(std::size_t end)
{
    if (!open_.empty()) {
        return tl::unexpected(
                errorAt(end, fmt::format("{} collection(s) never closed", open_.size())));
    }
    if (d_.numberedReports) {
        for (const auto& f : d_.fields) {
            if (f.reportId == 0) {
                return makeError(ErrorCode::Corrupt,
                                 "HID report descriptor: some reports have IDs and some have "
                                 "none; a device must number all its reports or none");
            }
        }
    }
    return {};
}

} // namespace

Expected<ReportDescriptor> parseReportDescriptor(std::span<const std::uint8_t> bytes)
{
    return DescriptorParser().run(bytes);
}

} // namespace replica::hal::hid
