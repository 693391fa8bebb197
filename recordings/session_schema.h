// The written schema of a recording's session message (/replica/session, encodeSession): the
// reader holds it against this before decoding, so a damaged or hostile session is refused with
// the JSON path of the offending value and unknown keys are warned. The run configuration inside
// it ("config", a JSON string) has its own schema (platform/run_config_schema.h).
#pragma once

#include <pipeline/base/json_schema.h>

namespace replica::recordings {

const JsonSchema& sessionSchema();

} // namespace replica::recordings
