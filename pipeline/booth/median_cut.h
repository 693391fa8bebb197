// Median cut of a planar light's luminance image into point lights (Debevec 2005; variance
// minimisation after Viriyothai & Debevec 2009), with summed-area tables in double.
#pragma once

#include <vector>

#include <pipeline/booth/luminance_image.h>

namespace replica::pipeline::booth {

enum class SplitRule {
    EnergyMedian,     // Debevec: cut the longest side where the energy halves
    VarianceMinimise, // Viriyothai & Debevec: cut where the larger half-variance is smallest
};

struct MedianCutOptions {
    int count = 32;
    SplitRule rule = SplitRule::VarianceMinimise;
    bool longestAxisOnly = false; // VM: search only the longest side (default: both sides)
    double texelWidthM = 1.0; // texel pitch along x and y, so "longest" and variance are in metres
    double texelHeightM = 1.0;
};

struct RegionLight {
    double sumCdM2 = 0.0;   // summed luminance of the region's texels (eq. 1's L_n)
    double centroidX = 0.0; // energy centroid, texel coordinates (texel x spans [x, x+1])
    double centroidY = 0.0;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0; // region [x0, x1) x [y0, y1)
};

// Summed-area tables of L, L x, L y, L x^2, L y^2 with coordinates in metres relative to the image
// centre (double: the x^2 sums of a large HDR image lose a float's mantissa to cancellation).
class LuminanceSat
{
public:
    LuminanceSat(const LuminanceImage& img, double texelWidthM, double texelHeightM);

    struct Moments {
        double l = 0.0, lx = 0.0, ly = 0.0, lxx = 0.0, lyy = 0.0;
    };
    Moments region(int x0, int y0, int x1, int y1) const;
    // Energy-weighted moment of inertia about the region's centroid (m^2 cd/m^2); 0 for no energy.
    double variance(int x0, int y0, int x1, int y1) const;

    double toTexelX(double xm) const { return xm / sx_ + 0.5 * w_; }
    double toTexelY(double ym) const { return ym / sy_ + 0.5 * h_; }

private:
    int w_, h_;
    double sx_, sy_;
    std::vector<Moments> t_; // (w+1) x (h+1)
};

// Splits until options.count regions exist or no region can be split (one texel, or no energy).
// Zero-energy regions keep power 0 and their geometric centre (never a NaN centroid). An all-zero
// image gives one zero-power light.
std::vector<RegionLight> medianCut(const LuminanceImage& img, const MedianCutOptions& options);

} // namespace replica::pipeline::booth
