// Spectral CSV parsing with file:line error messages.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/csv/csv_cells.h>

namespace replica::pipeline::colour {
namespace {} // namespace

Expected<SpectralTable> parseSpectralCsv(const std::string& text, const std::string& source)
{
    if (auto ok = checkTableLimits(text, source, ','); !ok) {
        return tl::unexpected(ok.error());
    }
    SpectralTable table;
    table.source = source;
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    bool haveHeader = false;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') {
            line.pop_back();
        }
        if (line.empty() || line[0] == '#') {
            continue;
        }
        auto cells = csv::splitCsvRow(line);
        if (!haveHeader) {
            if (cells.size() < 2 || cells[0] != "wavelength_nm") {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("{}:{}: header must be 'wavelength_nm,<name>,...'",
                                             source, lineNo));
            }
            for (std::size_t c = 1; c < cells.size(); ++c) {
                if (cells[c].empty()) {
                    return makeError(ErrorCode::InvalidArgument,
                                     fmt::format("{}:{}: column {} has an empty name", source,
                                                 lineNo, c + 1));
                }
            }
            table.columns.assign(cells.begin() + 1, cells.end());
            table.headerLine = lineNo;
            haveHeader = true;
            continue;
        }
        if (cells.size() != table.columns.size() + 1) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}:{}: {} cells, expected {} (wavelength_nm and {} columns)",
                                source, lineNo, cells.size(), table.columns.size() + 1,
                                table.columns.size()));
        }
        double wl = 0.0;
        if (!csv::parseFiniteNumber(cells[0], wl)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}:{}: wavelength '{}' is not a number", source, lineNo,
                                         csv::shownCell(cells[0])));
        }
        if (!table.wavelengthNm.empty() && !(wl > table.wavelengthNm.back())) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}:{}: wavelength {} nm does not increase (previous {} nm)",
                                source, lineNo, wl, table.wavelengthNm.back()));
        }
        std::vector<double> row(table.columns.size());
        for (std::size_t c = 0; c < row.size(); ++c) {
            if (!csv::parseFiniteNumber(cells[c + 1], row[c])) {
                return makeError(ErrorCode::InvalidArgument,
                                 fmt::format("{}:{}: column '{}' value '{}' is not a finite number",
                                             source, lineNo, csv::shownCell(table.columns[c]),
                                             csv::shownCell(cells[c + 1])));
            }
        }
        table.wavelengthNm.push_back(wl);
        table.rows.push_back(std::move(row));
        table.rowLines.push_back(lineNo);
    }
    if (!haveHeader) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no header line 'wavelength_nm,...' found", source));
    }
    if (table.rows.size() < 2) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: needs at least two data rows, found {}", source,
                                     table.rows.size()));
    }
    return table;
}

Expected<SpectralTable> loadSpectralCsv(const std::filesystem::path& path)
{
    auto text = readInputFile(path, kMaxCsvBytes, "spectral table");
    if (!text) {
        if (text.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot open spectral table (does the file exist?)",
                                         path.string()));
        }
        return tl::unexpected(text.error());
    }
    return parseSpectralCsv(*text, path.string());
}

Expected<std::vector<double>> SpectralTable::values(const std::string& column) const
{
    const auto it = std::find(columns.begin(), columns.end(), column);
    if (it == columns.end()) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}:{}: no column named '{}' in the header", source,
                                     headerLine, column));
    }
    const auto c = static_cast<std::size_t>(it - columns.begin());
    std::vector<double> out;
    out.reserve(rows.size());
    for (const auto& row : rows) {
        out.push_back(row[c]);
    }
    return out;
}

Expected<Spectrum> SpectralTable::spectrum(const std::string& column, GridSampling sampling) const
{
    auto v = values(column);
    if (!v) {
        return tl::unexpected(v.error());
    }
    // Name the offending line when the data stop short of the working grid.
    if (!wavelengthNm.empty() && wavelengthNm.front() > kFirstNm) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}:{}: data start at {} nm but must cover {}-{} nm", source,
                                     rowLines.empty() ? 0 : rowLines.front(), wavelengthNm.front(),
                                     kFirstNm, kLastNm));
    }
    if (!wavelengthNm.empty() && wavelengthNm.back() < kLastNm) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}:{}: data end at {} nm but must cover {}-{} nm", source,
                                     rowLines.empty() ? 0 : rowLines.back(), wavelengthNm.back(),
                                     kFirstNm, kLastNm));
    }
    return resampleToWorkingGrid(SampledSpectrum{wavelengthNm, std::move(*v)},
                                 fmt::format("{}: column '{}'", source, column), sampling);
}

Expected<std::vector<Spectrum>> SpectralTable::allSpectra(GridSampling sampling) const
{
    std::vector<Spectrum> out;
    for (const auto& name : columns) {
        auto s = spectrum(name, sampling);
        if (!s) {
            return tl::unexpected(s.error());
        }
        out.push_back(*s);
    }
    return out;
}

Expected<void> checkWorkingGrid(const SpectralTable& table)
{
    if (table.wavelengthNm.size() != kBands) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("{}: has {} wavelength rows, expected the {} of the working grid "
                            "({}-{} nm every {} nm)",
                            table.source, table.wavelengthNm.size(), kBands, kFirstNm, kLastNm,
                            kStepNm));
    }
    for (std::size_t i = 0; i < kBands; ++i) {
        if (table.wavelengthNm[i] != bandCentreNm(i)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}: wavelength row {} is {} nm, expected {} nm (the working grid)",
                                table.source, i + 1, table.wavelengthNm[i], bandCentreNm(i)));
        }
    }
    return {};
}

Expected<Spectrum> workingGridColumn(const SpectralTable& table, const std::string& column)
{
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
        if (table.columns[c] != column) {
            continue;
        }
        Spectrum s;
        for (std::size_t i = 0; i < kBands && i < table.rows.size(); ++i) {
            s[i] = table.rows[i][c];
        }
        return s;
    }
    return makeError(ErrorCode::InvalidArgument,
                     fmt::format("{}: no column named '{}'", table.source, column));
}

} // namespace replica::pipeline::colour
