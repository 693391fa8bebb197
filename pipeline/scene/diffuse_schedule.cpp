// The cached diffuse term's refresh schedule.
#include <algorithm>

#include <pipeline/scene/diffuse_schedule.h>

namespace replica::pipeline::scene {

DiffuseTilt
nextDiffuse(const std::optional<DiffuseTilt>& last, double heldRad, bool lightChanged, int slices)
{
    const int k = std::max(slices, 1);
    if (lightChanged || !last) {
        return {heldRad, std::nullopt, 0};
    }
    DiffuseTilt d = *last;
    if (!d.refreshRad && heldRad != d.shownRad) {
        if (k == 1) {
            d.shownRad = heldRad;
        } else {
            d.refreshRad = heldRad;
            d.refreshBands = 0;
        }
    }
    if (d.refreshRad && ++d.refreshBands == k) {
        d.shownRad = *d.refreshRad;
        d.refreshRad.reset();
        d.refreshBands = 0;
    }
    return d;
}

bool diffuseFollows(const DiffuseTilt& had, const DiffuseTilt& want, int slices)
{
    // The held tilt that could have led there: a refresh's target, else the tilt shown (while a
    // refresh is under way the held tilt does not matter).
    return nextDiffuse(had, diffuseTarget(want), false, slices) == want;
}

} // namespace replica::pipeline::scene
