// The content key of a state's light.
#include <cstring>

#include <pipeline/scene/scene_state.h>

namespace replica::pipeline::scene {
namespace {

void fnv1a(std::uint64_t& h, const void* data, std::size_t n)
{
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 0x100000001b3ULL;
    }
}

} // namespace

std::uint64_t lightKey(int lampIndex, const colour::Spectrum& illuminant, double luminanceCdM2)
{
    std::uint64_t h = 0xcbf29ce484222325ULL;
    fnv1a(h, &lampIndex, sizeof lampIndex);
    if (lampIndex < 0) {
        // Direct-sensor mode: the light is the sensed spectrum at the sensed luminance.
        fnv1a(h, illuminant.v.data(), sizeof(double) * illuminant.v.size());
        fnv1a(h, &luminanceCdM2, sizeof luminanceCdM2);
    }
    return h;
}

std::uint64_t lightKey(const SceneState& state)
{
    return lightKey(state.lampIndex, state.illuminant, state.emitterLuminanceCdM2);
}

} // namespace replica::pipeline::scene
