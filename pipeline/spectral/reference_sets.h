// The reference spectra Replica ships (data/spectra/): named reflectance sets and CIE illuminants,
// loaded onto the working grid.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::spectral {

using colour::Spectrum;

// Spectra with their column names, in file order.
struct NamedSpectra {
    std::string source;
    std::vector<std::string> names;
    std::vector<Spectrum> spectra;

    std::size_t size() const { return spectra.size(); }
    void append(const NamedSpectra& other);
};

// Every value column of a spectral CSV, resampled to the working grid: lights averaged over each
// band, reflectances taken at the band centres (colour::GridSampling).
Expected<NamedSpectra> loadNamedSpectra(const std::filesystem::path& path,
                                        colour::GridSampling sampling);

// A reflectance set from a spectral CSV, taken at the band centres, every value checked to be a
// reflectance: from kMinReflectance (a small negative is measurement noise; -0.1 gave L* = -88.8)
// to kMaxReflectance (a fluorescent sample reflects a little more than 1, never 10 times the
// light). A value outside is an error naming the file, line and column.
constexpr double kMinReflectance = -0.05;
constexpr double kMaxReflectance = 10.0;
Expected<NamedSpectra> loadReflectances(const std::filesystem::path& path);

// A light's scale does not matter to a colour evaluation (its white is normalised), but values near
// either end of a double's range overflow or underflow once multiplied out, and were then blamed
// on the reflectances: an error naming 'source' (the light's file) when its XYZ is not finite or
// its Y beyond kMaxLightY (overflow), its Y below kMinLightY while it has light (underflow), or Y
// is not above 0 (no light).
constexpr double kMaxLightY = 1e30;
constexpr double kMinLightY = 1e-30;
// A band below -kMaxNegativeLightFraction of the peak is refused too: noise about a measured
// spectrum's dark level dips below 0 by a fraction of a percent, a wrong file by more.
constexpr double kMaxNegativeLightFraction = 0.01;
Expected<void>
checkLightScale(const colour::Observer& obs, const Spectrum& light, const std::string& source);

// Reflectance sets by name: "colorchecker" (BabelColor average, 24 patches), "colorchecker-ohta",
// "ces99" (CIE 224:2017 / TM-30 evaluation samples), "tcs14" (CIE 13.3 test colour samples); the
// 5 nm sets taken at the band centres.
Expected<NamedSpectra> loadReflectanceSet(const std::filesystem::path& dataDir,
                                          const std::string& name);
std::vector<std::string> reflectanceSetNames();

// One CIE illuminant by its name in the shipped tables ("A", "D50", "D65", "F1".."F12",
// "FL3.1".."FL3.15", "LED-B1".."LED-V2"), from the finest table available.
Expected<Spectrum> loadCieIlluminant(const std::filesystem::path& dataDir, const std::string& name);
// All of them, in that order.
Expected<NamedSpectra> loadAllCieIlluminants(const std::filesystem::path& dataDir);

// The lights of the accuracy table (docs/accuracy.md): A, D50, D65, F2, F7, F8, F11 and LED-B4
// (5000 K phosphor-converted white LED).
std::vector<std::string> evaluationLightNames();

} // namespace replica::pipeline::spectral
