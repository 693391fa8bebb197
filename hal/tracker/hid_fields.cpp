// HID report fields: units, the descriptor's lookups, and reading and writing field values in
// report bytes (HID 1.11, 5.8 and 6.2.2.7).
#include <algorithm>
#include <cmath>
#include <iterator>

#include <hal/tracker/hid_descriptor.h>

namespace replica::hal::hid {

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

std::optional<double> physicalValue(const HidField& f, std::int64_t logical)
{
    const auto x = static_cast<double>(logical);
    if (f.physicalMin == 0 && f.physicalMax == 0) {
        return x;
    }
    if (f.logicalMax == f.logicalMin) {
        return std::nullopt;
    }
    // In doubles: the differences of 64-bit limits may not fit an int64.
    const double logicalSpan =
            static_cast<double>(f.logicalMax) - static_cast<double>(f.logicalMin);
    const double physicalSpan =
            static_cast<double>(f.physicalMax) - static_cast<double>(f.physicalMin);
    return (x - static_cast<double>(f.logicalMin)) * physicalSpan / logicalSpan +
           static_cast<double>(f.physicalMin);
}

HidField joinedBytes(const ReportDescriptor& d, const HidField& first)
{
    const auto at = std::find_if(d.fields.begin(), d.fields.end(),
                                 [&](const HidField& f) { return &f == &first; });
    if (at == d.fields.end() || first.bitSize != 8) {
        return first;
    }
    HidField joined = first;
    for (auto it = std::next(at); it != d.fields.end() && joined.bitSize < 64; ++it) {
        if (it->type != first.type || it->reportId != first.reportId || it->usage != first.usage ||
            it->constant || it->bitSize != 8 || it->bitOffset != first.bitOffset + joined.bitSize) {
            break;
        }
        joined.bitSize += 8;
    }
    if (joined.bitSize > 8) {
        joined.logicalMin = 0;
        joined.logicalMax = 0;
        joined.physicalMin = 0;
        joined.physicalMax = 0;
    }
    return joined;
}

} // namespace replica::hal::hid
