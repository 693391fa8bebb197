// The cell-level rules every CSV reader of the project shares (spectral tables, display
// measurements and viewing-angle tables, the colour CLI's pairs): trimming, splitting a row at
// commas, and reading a cell as a finite number. One set of rules, so that a file one command
// accepts is not refused by another for the spelling of a number.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace replica::pipeline::csv {

// s without leading and trailing spaces, tabs and carriage returns, and without a leading UTF-8
// byte order mark.
std::string trimCell(std::string_view s);

// The trimmed cells of one row; a trailing comma gives a trailing empty cell, so that a row with
// a missing last value is counted as such rather than silently shortened. An empty line is one
// empty cell.
// A cell in double quotes (RFC 4180) may hold commas, and "" for a quote.
std::vector<std::string> splitCsvRow(std::string_view line);

// True when the whole cell is one finite decimal number: an optional sign ('+' or '-'), digits
// with an optional '.', an optional exponent. Read with std::from_chars, so the C locale's
// decimal separator does not matter (a process running under a comma-decimal locale reads the
// same files), and hexadecimal, "inf" and "nan" are refused. 'v' is written only on success.
bool parseFiniteNumber(std::string_view cell, double& v);

// A cell, or a line, of a file as an error message quotes it: control characters as \xNN (a
// terminal escape in a hostile file is shown, never run; a NUL does not cut the message short) and
// at most kShownCellChars characters, then "..." (a 10 MB cell is not a 10 MB message). Every
// reader quotes what it read through it.
constexpr std::size_t kShownCellChars = 40;
std::string shownCell(std::string_view cell);

// One data line of a CSV text: its 1-based line number, the line trimmed (trimCell) and its
// cells (splitCsvRow).
struct CsvLine {
    int number = 0;
    std::string text;
    std::vector<std::string> cells;
};

// The data lines of 'text' (lines end at '\n'): each line trimmed, blank lines and '#' comment
// lines left out.
std::vector<CsvLine> csvLines(const std::string& text);

} // namespace replica::pipeline::csv
