// The written schema of the run configuration a recording carries (RunConfig::toJson, plus the
// informational run_options and site objects 'replica run' adds): RunConfig::fromJson holds a
// recording's configuration against it before reading a field, so a hostile or damaged
// recording is refused with the JSON path of the offending value, and unknown keys are warned.
#pragma once

#include <pipeline/base/json_schema.h>

namespace replica::platform {

const JsonSchema& runConfigSchema();

} // namespace replica::platform
