// The cached diffuse term's refresh schedule.
#include <algorithm>
#include <cmath>

#include <pipeline/scene/diffuse_schedule.h>

namespace replica::pipeline::scene {

DiffuseTilt nextDiffuse(const std::optional<DiffuseTilt>& last,
                        double heldRad,
                        bool lightChanged,
                        int slices,
                        double maxLagRad,
                        std::optional<double> aimRad)
{
    const int k = std::max(slices, 1);
    // '!(lag <= max)' also draws whole on a NaN lag (a non-finite held tilt never reaches here:
    // the estimator holds finite tilts only).
    if (lightChanged || !last || !(std::abs(heldRad - last->shownRad) <= maxLagRad)) {
        return {heldRad, std::nullopt, 0};
    }
    DiffuseTilt d = *last;
    const double aim = aimRad.value_or(heldRad);
    if (!d.refreshRad && aim != d.shownRad) {
        if (k == 1) {
            d.shownRad = aim;
        } else {
            d.refreshRad = aim;
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

DiffuseDraw diffuseDraw(const std::optional<DiffuseTilt>& last,
                        const DiffuseTilt& now,
                        bool lightChanged,
                        int slices)
{
    const int k = std::max(slices, 1);
    DiffuseDraw d{now.shownRad, std::nullopt};
    if (now.refreshRad) {
        d.band = DiffuseBand{*now.refreshRad, now.refreshBands - 1, k};
    } else if (!lightChanged && last && last->refreshRad && k > 1 && last->refreshBands + 1 == k &&
               now.shownRad == *last->refreshRad) {
        // The refresh's last band, drawn this frame: it shows its tilt from this frame on.
        d.band = DiffuseBand{*last->refreshRad, k - 1, k};
    }
    return d;
}

} // namespace replica::pipeline::scene
