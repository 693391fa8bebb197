// CIEDE2000 colour difference (CIE 142-2001), implemented as in Sharma, Wu & Dalal (2005).
#pragma once

#include <pipeline/colour/cielab.h>

namespace replica::pipeline::colour {

struct Ciede2000Weights {
    double kL = 1.0, kC = 1.0, kH = 1.0; // parametric factors; 1 for the reference conditions
};

// Symmetric in its arguments. Zero-chroma colours get hue 0 (Sharma eq. 7), and the mean hue of a
// pair more than 180 degrees apart wraps around (eq. 14).
double ciede2000(const Lab& lab1, const Lab& lab2, const Ciede2000Weights& w = {});

} // namespace replica::pipeline::colour
