// Offline capture of a booth light (paper: "Modeling the Light Booth Illumination"): recover the
// camera response and merge a bracketed 8-bit exposure series into HDR (Debevec & Malik 1997),
// scale to absolute luminance with a calibration, and warp onto the ceiling plane from four marked
// corners.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/booth/luminance_image.h>

namespace replica::pipeline::booth {

struct Exposure {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> z; // pixel values 0..255, row-major
    double seconds = 0.0;
};

// g(z) = ln(exposure) for pixel value z, with g(128) = 0 (relative scale).
struct ResponseCurve {
    std::array<double, 256> g{};
};

// Least-squares solve of Debevec & Malik's system over samplePixels locations spread over the
// frame, hat weights, smoothness weight lambda. Fails if the series has fewer than 2 exposures,
// sizes differ or times are not positive.
Expected<ResponseCurve>
recoverResponse(const std::vector<Exposure>& series, int samplePixels = 120, double lambda = 20.0);

// Relative radiance per pixel: exp of the weighted mean of g(z) - ln(dt). Fails naming the pixel if
// it is saturated in every exposure (the series needs a shorter exposure).
Expected<LuminanceImage> mergeHdr(const std::vector<Exposure>& series, const ResponseCurve& curve);

// Projective map taking the ceiling's unit square (u, v) to image pixels, from the images of its
// four corners (u, v) = (0,0), (1,0), (1,1), (0,1).
struct Homography {
    std::array<double, 9> h{};
    glm::dvec2 apply(double u, double v) const;
};

Expected<Homography> homographyFromCorners(const std::array<glm::dvec2, 4>& corners);

// Resamples the (calibrated) HDR image onto a texelsX x texelsY grid on the ceiling; 2x2
// supersampling per texel, bilinear in the image. Fails if a corner maps outside the image.
Expected<LuminanceImage>
warpToCeiling(const LuminanceImage& hdr, const Homography& h, int texelsX, int texelsY);

} // namespace replica::pipeline::booth
