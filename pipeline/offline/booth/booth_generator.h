// The shipped booth: three ceiling lights like the paper's (tungsten CIE A, fluorescent D50
// simulator CIE F8, fluorescent D65 simulator CIE F7) with the non-uniformity of real diffusers.
#pragma once

#include <filesystem>

#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_model.h>

namespace replica::pipeline::booth {

// Ceiling emitter geometry shared by the three lights (booth frame, metres, y up).
struct CeilingGeometry {
    glm::dvec3 centre{0.0, 0.62, -0.05};
    double widthM = 1.0; // along x
    double depthM = 0.5; // along z
    int texelsX = 256;
    int texelsZ = 128;
};

// Deterministic: same output on every machine (no library random distributions).
Expected<Booth> generateShippedBooth(const std::filesystem::path& dataDir,
                                     const CeilingGeometry& g = {});

} // namespace replica::pipeline::booth
