// The shipped scenes: a semi-gloss ColorChecker, two metamer targets (matched under tungsten, as
// the paper's, and under the D65 simulator), a varnished painting-like surface (canvas weave,
// impasto strokes, measured reflectances) and a glossy cylinder. Deterministic on every machine.
#pragma once

#include <filesystem>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::surface {

// kind: "colorchecker", "metamer" (pairs matched under tungsten, the paper's Fig. 7),
// "metamer-d65" (pairs matched under the booth's D65 simulator), "painting" or "glossy-cylinder"
// (a curved high-gloss surface, the paper's Fig. 5).
Expected<SurfaceScene> generateScene(const std::string& kind, const std::filesystem::path& dataDir);

// Metamer pairs: r2 = r1 + a metameric black for 'light' (CIE 1931), scaled to stay in [0.02,
// 0.95]. The pair matches exactly under 'light' and differs under others.
colour::Spectrum metamericBlack(const colour::Observer& obs,
                                const colour::Spectrum& light,
                                const colour::Spectrum& shape);

} // namespace replica::pipeline::surface
