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
    DiffuseDraw d{now.shownRad, std::nullopt, std::nullopt, 0.0};
    if (now.refreshRad) {
        d.band = DiffuseBand{*now.refreshRad, now.refreshBands - 1, k};
    } else if (!lightChanged && last && last->refreshRad && k > 1 && last->refreshBands + 1 == k &&
               now.shownRad == *last->refreshRad) {
        // The refresh's last band, drawn this frame: it shows its tilt from this frame on.
        d.band = DiffuseBand{*last->refreshRad, k - 1, k};
    }
    return d;
}

namespace {

bool holds(const std::vector<double>& nodes, double rad)
{
    return std::find(nodes.begin(), nodes.end(), rad) != nodes.end();
}

// The nodes nearest the held tilt below and above it (or at it), and the nearest of all.
struct Bracket {
    std::optional<double> lo, hi, nearest;
    // Whether the frame can interpolate: a node at the held tilt, or one each side at most a
    // step apart.
    bool spans(double stepRad) const
    {
        return lo && hi && (*lo == *hi || *hi - *lo <= stepRad * (1.0 + 1e-9));
    }
};
Bracket bracketOf(const std::vector<double>& nodes, double heldRad)
{
    Bracket b;
    for (const double node : nodes) {
        if (node <= heldRad && (!b.lo || node > *b.lo)) {
            b.lo = node;
        }
        if (node >= heldRad && (!b.hi || node < *b.hi)) {
            b.hi = node;
        }
        if (!b.nearest || std::abs(node - heldRad) < std::abs(*b.nearest - heldRad)) {
            b.nearest = node;
        }
    }
    return b;
}

// The node a refresh draws, if any: the held tilt's step's ends (the nearer first) while the
// nodes do not span it; otherwise, while the panel moves, the first multiple of the step past
// the nodes that span it, that way.
std::optional<double> nextNode(const std::vector<double>& nodes,
                               const Bracket& b,
                               double heldRad,
                               double stepRad,
                               int direction)
{
    if (!b.spans(stepRad)) {
        const double below = stepRad * std::floor(heldRad / stepRad);
        const double above = below + stepRad;
        const bool nearerBelow = heldRad - below <= above - heldRad;
        for (const double node : {nearerBelow ? below : above, nearerBelow ? above : below}) {
            if (!holds(nodes, node)) {
                return node;
            }
        }
        return std::nullopt;
    }
    if (direction == 0) {
        return std::nullopt;
    }
    const double ahead = direction > 0 ? stepRad * (std::floor(*b.hi / stepRad) + 1.0)
                                       : stepRad * (std::ceil(*b.lo / stepRad) - 1.0);
    return holds(nodes, ahead) ? std::nullopt : std::optional<double>(ahead);
}

} // namespace

DiffuseNodeStep nextDiffuseNodes(const std::optional<DiffuseNodes>& last,
                                 double heldRad,
                                 bool lightChanged,
                                 int slices,
                                 double stepRad,
                                 double maxLagRad,
                                 int direction)
{
    const int k = std::max(slices, 1);
    if (lightChanged || !last || !(stepRad > 0.0) || !std::isfinite(heldRad)) {
        return {{{heldRad}, std::nullopt, 0}, {heldRad, std::nullopt, std::nullopt, 0.0}};
    }
    DiffuseNodeStep out{*last, {heldRad, std::nullopt, std::nullopt, 0.0}};
    DiffuseNodes& n = out.nodes;
    if (!n.refreshRad) {
        n.refreshRad = nextNode(n.nodes, bracketOf(n.nodes, heldRad), heldRad, stepRad, direction);
        n.refreshBands = 0;
    }
    std::optional<DiffuseBand> band;
    if (n.refreshRad) {
        band = DiffuseBand{*n.refreshRad, n.refreshBands, k};
        if (++n.refreshBands == k) {
            n.nodes.push_back(*n.refreshRad);
            n.refreshRad.reset();
            n.refreshBands = 0;
        }
    }
    // What the frame shows, with the node this frame's band completed.
    const Bracket b = bracketOf(n.nodes, heldRad);
    DiffuseDraw& d = out.draw;
    d.band = band;
    if (b.spans(stepRad) && *b.lo == *b.hi) {
        d.shownRad = *b.lo;
    } else if (b.spans(stepRad)) {
        d.shownRad = *b.lo;
        d.mixRad = *b.hi;
        d.mix = (heldRad - *b.lo) / (*b.hi - *b.lo); // lo < held < hi: in (0, 1)
    } else if (b.nearest && std::abs(*b.nearest - heldRad) <= maxLagRad) {
        d.shownRad = *b.nearest;
    } else {
        // Too far from every node: the held tilt whole, now. The whole draw replaces what a
        // refresh's bands drew with (the diffuse grid), so a refresh under way starts again; a
        // band that completed its node this frame is drawn first and stays.
        n.nodes.push_back(heldRad);
        n.refreshRad.reset();
        n.refreshBands = 0;
        const bool completed = band && band->band + 1 == band->bands;
        d = {heldRad, completed ? band : std::nullopt, std::nullopt, 0.0};
    }
    // Forget the nodes farthest from the held tilt (never one the frame shows).
    while (n.nodes.size() > kMaxDiffuseNodes) {
        auto farthest = n.nodes.end();
        for (auto it = n.nodes.begin(); it != n.nodes.end(); ++it) {
            if (*it == d.shownRad || (d.mixRad && *it == *d.mixRad)) {
                continue;
            }
            if (farthest == n.nodes.end() ||
                std::abs(*it - heldRad) > std::abs(*farthest - heldRad)) {
                farthest = it;
            }
        }
        if (farthest == n.nodes.end()) {
            break;
        }
        n.nodes.erase(farthest);
    }
    return out;
}

} // namespace replica::pipeline::scene
