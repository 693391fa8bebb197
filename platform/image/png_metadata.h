// What a PNG of a shown frame says about itself: the colour space its pixels are in and when the
// frame was shown.
//
// Pixels are the panel's drive values (the inverse display model's output), so the honest colour
// space is the panel's: an iCCP chunk with the display profile as ICC (pipeline/display/
// icc_profile.h, the profile 'display fit --icc' writes, its tone curves as 256 entries: exact at
// each 8-bit value). Only where no profile can be made (a model without a white) is the image
// called sRGB (sRGB, gAMA, cHRM chunks), which is what a viewer assumes of an untagged PNG
// anyway. libpng 1.6.39 (Debian 12) cannot write cICP, and a display profile is no coding-
// independent code point.
//
// The time: tIME (the frame's wall-clock time, UTC, to the second) and tEXt "Creation Time" (ISO
// 8601 UTC, to the millisecond), and tEXt "Replica frame" (frame index and session second).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <png.h>

namespace replica::platform {

struct PngMetadata {
    std::vector<std::uint8_t> icc; // iCCP: the profile the pixels are in; empty: see srgb
    std::string iccName = "display";
    bool srgb = false;                  // with no icc: sRGB, gAMA and cHRM chunks
    std::optional<std::int64_t> unixNs; // tIME and tEXt "Creation Time"
    std::vector<std::pair<std::string, std::string>> text; // further tEXt chunks (keyword, text)
};

// A shown frame's metadata: the display profile (icc; empty: sRGB), the frame's tick on the
// recording's clock (wallStartNs 0: unknown, no time chunks) and its frame index.
PngMetadata shownFrameMetadata(const std::vector<std::uint8_t>& icc,
                               const std::string& profileName,
                               std::int64_t wallStartNs,
                               std::int64_t tickNs,
                               std::uint64_t frameIndex);

// A PNG keyword (tEXt, iCCP name): printable Latin-1 (here ASCII), no leading, trailing or double
// spaces, 1-79 characters.
std::string pngKeyword(const std::string& s);

// The chunks in libpng's terms, prepared before libpng's setjmp (apply allocates nothing that
// needs a destructor, so a longjmp out of it leaks nothing).
class PngChunks
{
public:
    explicit PngChunks(const PngMetadata* meta);
    PngChunks(const PngChunks&) = delete; // text_ points into strings_
    PngChunks& operator=(const PngChunks&) = delete;
    void apply(png_structp png, png_infop info) const;

private:
    const PngMetadata* meta_;
    std::string iccName_;
    std::vector<std::string> strings_; // keyword, text, keyword, text, ...
    std::vector<png_text> text_;
    png_time time_{};
    bool hasTime_ = false;
};

} // namespace replica::platform
