// Median cut and variance-minimising cut over summed-area tables.
#include <algorithm>
#include <limits>

#include <pipeline/booth/median_cut.h>

namespace replica::pipeline::booth {

LuminanceSat::LuminanceSat(const LuminanceImage& img, double texelWidthM, double texelHeightM)
    : w_(img.width), h_(img.height), sx_(texelWidthM), sy_(texelHeightM),
      t_(static_cast<std::size_t>(w_ + 1) * static_cast<std::size_t>(h_ + 1))
{
    const auto idx = [this](int x, int y) {
        return static_cast<std::size_t>(y) * static_cast<std::size_t>(w_ + 1) +
               static_cast<std::size_t>(x);
    };
    for (int y = 0; y < h_; ++y) {
        Moments row;
        const double ym = (y + 0.5 - 0.5 * h_) * sy_;
        for (int x = 0; x < w_; ++x) {
            const double l = img.at(x, y);
            const double xm = (x + 0.5 - 0.5 * w_) * sx_;
            row.l += l;
            row.lx += l * xm;
            row.ly += l * ym;
            row.lxx += l * xm * xm;
            row.lyy += l * ym * ym;
            const Moments& up = t_[idx(x + 1, y)];
            Moments& m = t_[idx(x + 1, y + 1)];
            m.l = up.l + row.l;
            m.lx = up.lx + row.lx;
            m.ly = up.ly + row.ly;
            m.lxx = up.lxx + row.lxx;
            m.lyy = up.lyy + row.lyy;
        }
    }
}

LuminanceSat::Moments LuminanceSat::region(int x0, int y0, int x1, int y1) const
{
    const auto at = [this](int x, int y) -> const Moments& {
        return t_[static_cast<std::size_t>(y) * static_cast<std::size_t>(w_ + 1) +
                  static_cast<std::size_t>(x)];
    };
    const Moments& a = at(x1, y1);
    const Moments& b = at(x0, y1);
    const Moments& c = at(x1, y0);
    const Moments& d = at(x0, y0);
    Moments m;
    m.l = a.l - b.l - c.l + d.l;
    m.lx = a.lx - b.lx - c.lx + d.lx;
    m.ly = a.ly - b.ly - c.ly + d.ly;
    m.lxx = a.lxx - b.lxx - c.lxx + d.lxx;
    m.lyy = a.lyy - b.lyy - c.lyy + d.lyy;
    return m;
}

double LuminanceSat::variance(int x0, int y0, int x1, int y1) const
{
    const Moments m = region(x0, y0, x1, y1);
    if (!(m.l > 0.0)) {
        return 0.0;
    }
    return std::max(m.lxx + m.lyy - (m.lx * m.lx + m.ly * m.ly) / m.l, 0.0);
}

namespace {

struct Region {
    int x0, y0, x1, y1;
    double score; // what decides which region is split next
};

struct Cut {
    bool alongX = true; // cut position is an x coordinate
    int at = -1;
};

Cut chooseCut(const LuminanceSat& sat, const Region& r, const MedianCutOptions& o)
{
    const double wM = (r.x1 - r.x0) * o.texelWidthM;
    const double hM = (r.y1 - r.y0) * o.texelHeightM;
    const bool xLongest = wM >= hM;
    Cut best;
    if (o.rule == SplitRule::EnergyMedian) {
        // Longest side (if it can be cut; else the other), at the energy median.
        bool alongX = xLongest ? (r.x1 - r.x0 > 1) : !(r.y1 - r.y0 > 1);
        const int lo = alongX ? r.x0 : r.y0;
        const int hi = alongX ? r.x1 : r.y1;
        if (hi - lo < 2) {
            return best;
        }
        const double total = sat.region(r.x0, r.y0, r.x1, r.y1).l;
        double bestDiff = std::numeric_limits<double>::infinity();
        for (int c = lo + 1; c < hi; ++c) {
            const double left =
                    alongX ? sat.region(r.x0, r.y0, c, r.y1).l : sat.region(r.x0, r.y0, r.x1, c).l;
            const double diff = std::abs(2.0 * left - total);
            if (diff < bestDiff) {
                bestDiff = diff;
                best = Cut{alongX, c};
            }
        }
        return best;
    }
    double bestScore = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 2; ++axis) {
        const bool alongX = axis == 0;
        if (o.longestAxisOnly && alongX != xLongest) {
            continue;
        }
        const int lo = alongX ? r.x0 : r.y0;
        const int hi = alongX ? r.x1 : r.y1;
        for (int c = lo + 1; c < hi; ++c) {
            const double a =
                    alongX ? sat.variance(r.x0, r.y0, c, r.y1) : sat.variance(r.x0, r.y0, r.x1, c);
            const double b =
                    alongX ? sat.variance(c, r.y0, r.x1, r.y1) : sat.variance(r.x0, c, r.x1, r.y1);
            const double s = std::max(a, b);
            if (s < bestScore) {
                bestScore = s;
                best = Cut{alongX, c};
            }
        }
    }
    return best;
}

double
regionScore(const LuminanceSat& sat, const Region& r, const MedianCutOptions& o, double floor)
{
    if ((r.x1 - r.x0) * (r.y1 - r.y0) <= 1 || !(sat.region(r.x0, r.y0, r.x1, r.y1).l > floor)) {
        return -1.0; // cannot or need not be split
    }
    if (o.rule == SplitRule::EnergyMedian) {
        return sat.region(r.x0, r.y0, r.x1, r.y1).l; // the brightest region is split first
    }
    return sat.variance(r.x0, r.y0, r.x1, r.y1);
}

} // namespace

std::vector<RegionLight> medianCut(const LuminanceImage& img, const MedianCutOptions& options)
{
    std::vector<RegionLight> lights;
    if (img.width <= 0 || img.height <= 0) {
        return lights;
    }
    const LuminanceSat sat(img, options.texelWidthM, options.texelHeightM);
    // Region sums are differences of table entries: anything below this is cancellation noise, not
    // light, and must not produce a centroid.
    const double floor = 1e-12 * sat.region(0, 0, img.width, img.height).l;
    std::vector<Region> regions{{0, 0, img.width, img.height, 0.0}};
    regions[0].score = regionScore(sat, regions[0], options, floor);
    const int target = std::max(options.count, 1);
    while (static_cast<int>(regions.size()) < target) {
        // Split the region with the largest score (variance or energy); ties keep the earliest.
        std::size_t pick = 0;
        for (std::size_t k = 1; k < regions.size(); ++k) {
            if (regions[k].score > regions[pick].score) {
                pick = k;
            }
        }
        if (regions[pick].score < 0.0) {
            break;
        }
        const Region r = regions[pick];
        const Cut cut = chooseCut(sat, r, options);
        if (cut.at < 0) {
            regions[pick].score = -1.0;
            continue;
        }
        Region a = r;
        Region b = r;
        if (cut.alongX) {
            a.x1 = cut.at;
            b.x0 = cut.at;
        } else {
            a.y1 = cut.at;
            b.y0 = cut.at;
        }
        a.score = regionScore(sat, a, options, floor);
        b.score = regionScore(sat, b, options, floor);
        regions[pick] = a;
        regions.push_back(b);
    }
    for (const Region& r : regions) {
        const LuminanceSat::Moments m = sat.region(r.x0, r.y0, r.x1, r.y1);
        RegionLight l;
        l.x0 = r.x0;
        l.y0 = r.y0;
        l.x1 = r.x1;
        l.y1 = r.y1;
        if (m.l > floor && m.l > 0.0) {
            l.sumCdM2 = m.l;
            l.centroidX = std::clamp(sat.toTexelX(m.lx / m.l), static_cast<double>(r.x0),
                                     static_cast<double>(r.x1));
            l.centroidY = std::clamp(sat.toTexelY(m.ly / m.l), static_cast<double>(r.y0),
                                     static_cast<double>(r.y1));
        } else {
            l.centroidX = 0.5 * (r.x0 + r.x1);
            l.centroidY = 0.5 * (r.y0 + r.y1);
        }
        lights.push_back(l);
    }
    return lights;
}

} // namespace replica::pipeline::booth
