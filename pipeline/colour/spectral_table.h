// Reading spectral CSV tables: '#' comment lines, a header 'wavelength_nm,<name>,...', numeric
// rows.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::colour {

struct SpectralTable {
    std::string source;                    // file name, for messages
    std::vector<std::string> columns;      // value column names, header order
    std::vector<double> wavelengthNm;      // strictly increasing
    std::vector<std::vector<double>> rows; // rows[i][c]: value of column c at wavelengthNm[i]
    int headerLine = 0;                    // 1-based line numbers, for messages
    std::vector<int> rowLines;

    // The named column at the table's own wavelengths, or an error naming the file and column.
    Expected<std::vector<double>> values(const std::string& column) const;
    // The named column resampled to the working grid ('sampling': a light's band average or a
    // reflectance's value at the band centre), or an error naming the file and column.
    Expected<Spectrum> spectrum(const std::string& column, GridSampling sampling) const;
    // Every column resampled to the working grid, in header order.
    Expected<std::vector<Spectrum>> allSpectra(GridSampling sampling) const;
};

// Parses CSV text. 'source' names the file in messages ("file:line: problem").
Expected<SpectralTable> parseSpectralCsv(const std::string& text, const std::string& source);
Expected<SpectralTable> loadSpectralCsv(const std::filesystem::path& path);

// For tables that must already be on the working grid (channel bases: resampling a projection
// vector would change what it means): fails unless the wavelengths are exactly 380, 390, ..., 730
// nm.
Expected<void> checkWorkingGrid(const SpectralTable& table);
// The named column of such a table, taken as is.
Expected<Spectrum> workingGridColumn(const SpectralTable& table, const std::string& column);

} // namespace replica::pipeline::colour
