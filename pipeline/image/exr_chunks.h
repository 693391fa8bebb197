// A check of an OpenEXR file's pixel data that the C++ reader skips (image/exr.h calls it).
#pragma once

#include <string>

#include <pipeline/base/expected.h>

namespace replica::pipeline::image {

// Decodes every scan-line chunk of the file's first part with OpenEXR's core library, which
// refuses a chunk whose data do not decompress to the size the header gives it. The C++ reader
// does not: a header whose data window was edited (one 16384-pixel line where the chunks hold 16
// lines of 256) read as an image of zeros and garbage without an error. 'bytes' is the whole
// file; 'name' names it in the message. Tiled files pass (the C++ reader refuses them).
Expected<void> checkExrChunks(const std::string& bytes, const std::string& name);

} // namespace replica::pipeline::image
