// CIEDE2000 between two absolute XYZ under one reference white: the display stage's fit and test
// metric, on pipeline/colour's CIELAB and CIEDE2000.
#pragma once

#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>

namespace replica::pipeline::display {

inline double deltaE2000Xyz(const colour::Xyz& a, const colour::Xyz& b, const colour::Xyz& white)
{
    return colour::ciede2000(colour::xyzToLab(a, white), colour::xyzToLab(b, white));
}

} // namespace replica::pipeline::display
