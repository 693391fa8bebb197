// See session_schema.h.
#include <recordings/recording.h>
#include <recordings/session_schema.h>

namespace replica::recordings {

const JsonSchema& sessionSchema()
{
    using namespace json_schema;
    static const JsonSchema s = [] {
        const auto device = object({{"model", string(4096)},
                                    {"serial", string(4096)},
                                    {"firmware", string(4096)},
                                    {"source", string(16)}});
        std::vector<JsonSchemaField> fields{
                // Any integer: a version this reader does not know is refused after decoding,
                // with its own message (update replica).
                {"format_version", integer(0, 65535)},
                {"software", string(4096)},
                {"config", string(kMaxMessageBytes)},
                {"booth", string(4096)},
                {"scene", string(4096)},
                {"display_profile", string(4096)},
                // Unix time in ns: from 1970 to the end of int64 (2262).
                {"wall_clock_start_ns", integer(0, 9.2e18)},
        };
        // Each device kind's source; an optional kind is absent before it existed.
        for (const auto* k : deviceKinds()) {
            fields.push_back({k->name(), k->names().optional ? device.optional() : device});
        }
        return object(std::move(fields));
    }();
    return s;
}

} // namespace replica::recordings
