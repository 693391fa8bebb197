// The cell-level rules the display layer's measurement CSVs share: trimming, splitting a row at
// commas, and reading a cell as a finite number.
#pragma once

#include <string>
#include <vector>

namespace replica::pipeline::display {

// s without leading and trailing spaces, tabs and carriage returns.
std::string trimCell(const std::string& s);

// The trimmed cells of one row; a trailing comma gives a trailing empty cell, so that a row with
// a missing last value is counted as such rather than silently shortened.
std::vector<std::string> splitCsvRow(const std::string& line);

// True when the whole cell is one finite number (no trailing text, no NaN or Inf).
bool parseFiniteNumber(const std::string& s, double& v);

} // namespace replica::pipeline::display
