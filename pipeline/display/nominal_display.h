// The nominal (uncharacterised) display the appliance drives under '--uncalibrated': sRGB
// primaries, D65 white at a stated peak, a 2.2 power law. A stand-in, not a measurement.
#pragma once

#include <string>

#include <pipeline/display/display_model.h>

namespace replica::pipeline::display {

// 'name' identifies it in recordings (e.g. "srgb-like-800"); peak and black in cd/m^2, 8 bits.
DisplayModel nominalDisplayModel(const std::string& name, double peakWhiteCdM2, double blackCdM2);

} // namespace replica::pipeline::display
