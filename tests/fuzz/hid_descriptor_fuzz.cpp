// Fuzz target for the HID report-descriptor parser and the eye/head tracker layout search (what
// probe, '--tracker hid' and 'replay --reprocess' run on a device's or a recording's descriptor):
// any bytes parse or are refused, and whatever parses stays within the parser's limits
// (hal/tracker/hid_descriptor.h), with every field inside its report. Built with libFuzzer under
// clang (tests/fuzz/run_fuzz.sh); with REPLICA_FUZZ_STANDALONE it links standalone_driver.cpp.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <hal/tracker/hid_descriptor.h>
#include <hal/tracker/hid_eye_head.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    using namespace replica::hal::hid;
    const std::span<const std::uint8_t> bytes(data, size);
    const auto d = parseReportDescriptor(bytes);
    if (!d) {
        return 0;
    }
    if (size > kMaxDescriptorBytes || d->fields.size() > kMaxFields ||
        d->collections.size() > kMaxCollections) {
        __builtin_trap(); // a limit not held
    }
    std::vector<std::uint8_t> report(kMaxReportBytes + 1, 0xA5);
    for (const auto& f : d->fields) {
        if (f.collections.size() > kMaxCollectionDepth || f.bitSize == 0 ||
            (f.bitOffset + f.bitSize + 7) / 8 > d->reportBytes(f.type, f.reportId) ||
            d->reportBytes(f.type, f.reportId) > kMaxReportBytes + 1) {
            __builtin_trap(); // a field outside its report
        }
        // Every field of a report as long as the descriptor says reads back what is written.
        const auto wire = std::span(report).first(d->reportBytes(f.type, f.reportId));
        if (!f.constant && f.bitSize <= 63) {
            const std::int64_t v = f.isSigned() ? -1 : 1;
            insertField(f, wire, v);
            const auto back = extractField(f, wire);
            if (!back || *back != v) {
                __builtin_trap();
            }
        }
    }
    (void)eht::findLayout(*d);
    return 0;
}

#ifdef REPLICA_FUZZ_STANDALONE
#include "standalone_driver.h"

const std::size_t replica::fuzz::kKeepPrefix = 0;
#endif
