// CGATS tables through Little CMS 2's IT8 functions (cmsIT8LoadFromMem, cmsIT8GetDataRowCol,
// cmsIT8SaveToMem): lcms2 reads and writes the text; pipeline/offline/display/cgats.h checks
// Argyll's row layout and gives the rows their lines first.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/offline/display/cgats.h>

namespace replica::pipeline::display {

// The first table of 'text' as lcms2 reads it ('fields' and 'rowLines' from the layout scan,
// which has checked them). lcms2's own errors come back as source:LINE: its message.
Expected<CgatsTable> readIt8Table(const std::string& text,
                                  const std::string& source,
                                  std::size_t fields,
                                  const std::vector<int>& rowLines);

// The table as lcms2 writes it, tabs made spaces (Argyll's own files separate with spaces).
std::string writeIt8Table(const CgatsTable& table);

} // namespace replica::pipeline::display
