// The lamps this build knows, by the booth model's light names: the one table of their names,
// CIE reference spectra and nominal luminances. scene::loadDefaultBooth gives each booth light its
// lamp's fields from it; the booth generator (booth_generator.h) makes the shipped booth's lights
// from it.
#pragma once

#include <array>

namespace replica::pipeline::booth {

struct LampKind {
    const char* name;
    const char* file;            // the reference spectrum's table, under data/spectra/
    const char* column;          // its column there (and in the generator's 10 nm table)
    double nominalLuminanceCdM2; // the emitter's mean luminance with this lamp on
};

// In the shipped booth's order (the lamp index): tungsten CIE A, D50 fluorescent simulator CIE F8,
// D65 fluorescent simulator CIE F7.
inline constexpr std::array<LampKind, 3> kLampKinds = {{
        {"tungsten", "cie_illuminants_A_D50_D65_5nm_300_780.csv", "A", 2200.0},
        {"d50-fluorescent", "cie_illuminants_F1_F12_5nm_380_780.csv", "F8", 2600.0},
        {"d65-fluorescent", "cie_illuminants_F1_F12_5nm_380_780.csv", "F7", 2600.0},
}};

} // namespace replica::pipeline::booth
