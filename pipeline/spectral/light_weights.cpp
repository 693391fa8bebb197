// The shipped basis's light weights (light_weights.h).
#include <fmt/format.h>

#include <pipeline/spectral/light_weights.h>

namespace replica::pipeline::spectral {

std::vector<std::pair<std::string, double>> defaultLightWeights()
{
    return {{"A", 30.0}, {"F8", 60.0}, {"F7", 30.0}, {"D50", 10.0}, {"D65", 10.0}};
}

std::string defaultLightWeightsText()
{
    std::string out;
    for (const auto& [name, w] : defaultLightWeights()) {
        out += fmt::format("{}{}={:g}", out.empty() ? "" : ",", name, w);
    }
    return out;
}

} // namespace replica::pipeline::spectral
