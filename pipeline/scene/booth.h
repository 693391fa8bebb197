// The light booth: a planar ceiling emitter and the lamps it can show, in the booth frame (metres).
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_light.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::scene {

// Booth frame: right-handed, metres; origin on the booth floor at its centre, x to the right, y up,
// z out of the booth towards the viewer.
// The defaults are the shipped booth model's ceiling; loadDefaultBooth reads them from it.
struct Emitter {
    glm::dvec3 centreM{0.0, 0.62, -0.05};
    glm::dvec3 edgeUM{1.00, 0.0, 0.0}; // full edge vectors: the emitter spans centre +- edge/2
    glm::dvec3 edgeVM{0.0, 0.0, 0.50};
    glm::dvec3 normal{0.0, -1.0, 0.0}; // emits downwards into the booth
};

struct Lamp {
    std::string name;         // "tungsten", "d50-fluorescent", "d65-fluorescent"
    std::string spectrumFile; // under data/spectra/
    std::string spectrumColumn;
    double luminanceCdM2 = 0.0;  // mean luminance of the emitter with this lamp on
    colour::Spectrum spectrum{}; // relative SPD on the working grid (filled by loadBooth)
};

struct Booth {
    std::string id;
    Emitter emitter;
    std::vector<Lamp> lamps;
};

// The booth the appliance ships with: tungsten (CIE A), D50 fluorescent simulator (CIE F8) and D65
// fluorescent simulator (CIE F7) behind one diffuser. Spectra are read from dataDir/spectra; the
// emitter's geometry is the booth model's ceiling (dataDir/booth/booth.json), so that the flat
// renderer, pass 2 and the booth renderer share one booth. Fails when the model's lights do not
// share one ceiling.
Expected<Booth> loadDefaultBooth(const std::string& dataDir);

// Splits a uniform emitter into nu x nv equal cells, one point light at each cell centre (its
// intensity L times the cell's area; the cell is its region rectangle, of luminance L).
std::vector<booth::PointLight>
uniformGridLights(const Emitter& e, double luminanceCdM2, int nu, int nv);

} // namespace replica::pipeline::scene
