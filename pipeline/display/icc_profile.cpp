// ICC v4 display profile through Little CMS 2.
#include <algorithm>
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <glm/matrix.hpp>
#include <lcms2.h>

#include <pipeline/display/icc_profile.h>

namespace replica::pipeline::display {
namespace {

struct ProfileCloser {
    void operator()(void* p) const { cmsCloseProfile(static_cast<cmsHPROFILE>(p)); }
};
using ProfilePtr = std::unique_ptr<void, ProfileCloser>;

struct CurveFree {
    void operator()(cmsToneCurve* c) const { cmsFreeToneCurve(c); }
};

bool writeText(cmsHPROFILE h, cmsTagSignature sig, const std::string& text)
{
    cmsMLU* mlu = cmsMLUalloc(nullptr, 1);
    if (mlu == nullptr) {
        return false;
    }
    const bool ok =
            cmsMLUsetASCII(mlu, "en", "US", text.c_str()) != 0 && cmsWriteTag(h, sig, mlu) != 0;
    cmsMLUfree(mlu);
    return ok;
}

} // namespace

glm::dmat3 bradfordToD50(const glm::dvec3& white)
{
    // Columns of the Bradford cone matrix (glm is column-major).
    const glm::dmat3 b(glm::dvec3(0.8951, -0.7502, 0.0389), glm::dvec3(0.2664, 1.7135, -0.0685),
                       glm::dvec3(-0.1614, 0.0367, 1.0296));
    const glm::dvec3 d50(0.9642, 1.0, 0.8249);
    const glm::dvec3 src = b * (white / white.y);
    const glm::dvec3 dst = b * d50;
    const glm::dmat3 scale(glm::dvec3(dst.x / src.x, 0, 0), glm::dvec3(0, dst.y / src.y, 0),
                           glm::dvec3(0, 0, dst.z / src.z));
    return glm::inverse(b) * scale * b;
}

Expected<IccWriteReport> writeIccProfile(const DisplayModel& model,
                                         const std::filesystem::path& path)
{
    IccWriteReport report;
    report.crosstalkOmitted = model.hasCrosstalk();
    const glm::dvec3 white = model.whiteXyz();
    if (!(white.y > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the model's white has no luminance", path.string()));
    }
    glm::dvec3 b = glm::inverse(model.matrix) * model.blackXyz;
    for (int c = 0; c < 3; ++c) {
        if (b[c] < 0.0) {
            b[c] = 0.0;
            report.blackClipped = true;
        }
    }
    report.blackChannels = b;
    // Colorants: columns of M diag(1 + b), relative to white Y = 1, adapted to D50.
    const glm::dmat3 adapt = bradfordToD50(white);
    std::array<cmsCIEXYZ, 3> colorant{};
    for (int c = 0; c < 3; ++c) {
        const glm::dvec3 col = adapt * (model.matrix[c] * (1.0 + b[c]) / white.y);
        colorant[static_cast<std::size_t>(c)] = {col.x, col.y, col.z};
    }
    cmsHPROFILE h = cmsCreateProfilePlaceholder(nullptr);
    if (h == nullptr) {
        return makeError(ErrorCode::Io, "lcms2: cannot create a profile");
    }
    ProfilePtr guard(h);
    cmsSetProfileVersion(h, 4.3);
    cmsSetDeviceClass(h, cmsSigDisplayClass);
    cmsSetColorSpace(h, cmsSigRgbData);
    cmsSetPCS(h, cmsSigXYZData);
    cmsSetHeaderRenderingIntent(h, INTENT_RELATIVE_COLORIMETRIC);
    bool ok = writeText(h, cmsSigProfileDescriptionTag, model.name) &&
              writeText(h, cmsSigCopyrightTag, "No copyright; written by replica display fit") &&
              cmsWriteTag(h, cmsSigMediaWhitePointTag, cmsD50_XYZ()) != 0 &&
              cmsWriteTag(h, cmsSigRedColorantTag, &colorant[0]) != 0 &&
              cmsWriteTag(h, cmsSigGreenColorantTag, &colorant[1]) != 0 &&
              cmsWriteTag(h, cmsSigBlueColorantTag, &colorant[2]) != 0;
    // chad: the adaptation used, row-major as the tag stores it.
    cmsFloat64Number chad[9];
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            chad[r * 3 + c] = adapt[c][r];
        }
    }
    ok = ok && cmsWriteTag(h, cmsSigChromaticAdaptationTag, chad) != 0;
    const cmsCIEXYZ lumi{0.0, white.y, 0.0};
    ok = ok && cmsWriteTag(h, cmsSigLuminanceTag, &lumi) != 0;
    // TRCs sampled at 4096 points over the count range (the curv tag holds 16-bit values).
    constexpr int kSamples = 4096;
    const cmsTagSignature trcTags[3] = {cmsSigRedTRCTag, cmsSigGreenTRCTag, cmsSigBlueTRCTag};
    for (std::size_t c = 0; ok && c < 3; ++c) {
        std::vector<cmsFloat32Number> v(kSamples);
        const double bc = b[static_cast<int>(c)];
        for (int i = 0; i < kSamples; ++i) {
            const double d = model.maxCount() * static_cast<double>(i) / (kSamples - 1);
            v[static_cast<std::size_t>(i)] = static_cast<cmsFloat32Number>(
                    std::clamp((model.tone[c](d) + bc) / (1.0 + bc), 0.0, 1.0));
        }
        std::unique_ptr<cmsToneCurve, CurveFree> curve(
                cmsBuildTabulatedToneCurveFloat(nullptr, kSamples, v.data()));
        ok = curve != nullptr && cmsWriteTag(h, trcTags[c], curve.get()) != 0;
    }
    if (!ok) {
        return makeError(ErrorCode::Io, fmt::format("{}: lcms2 could not build the profile's tags",
                                                    path.string()));
    }
    if (cmsSaveProfileToFile(h, path.string().c_str()) == 0) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: cannot write the ICC profile", path.string()));
    }
    return report;
}

Expected<IccInfo> readIccInfo(const std::filesystem::path& path)
{
    ProfilePtr in(cmsOpenProfileFromFile(path.string().c_str(), "r"));
    if (!in) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: lcms2 cannot read the ICC profile", path.string()));
    }
    IccInfo info;
    info.version = cmsGetProfileVersion(in.get());
    info.displayClass = cmsGetDeviceClass(in.get()) == cmsSigDisplayClass;
    info.rgbToXyz =
            cmsGetColorSpace(in.get()) == cmsSigRgbData && cmsGetPCS(in.get()) == cmsSigXYZData;
    if (const auto* lumi = static_cast<const cmsCIEXYZ*>(cmsReadTag(in.get(), cmsSigLuminanceTag));
        lumi != nullptr) {
        info.luminanceCdM2 = lumi->Y;
    }
    char buf[256] = {};
    cmsGetProfileInfoASCII(in.get(), cmsInfoDescription, "en", "US", buf, sizeof buf);
    info.description = buf;
    return info;
}

Expected<std::vector<glm::dvec3>>
iccForward(const std::filesystem::path& path, const std::vector<glm::dvec3>& counts, int bitDepth)
{
    ProfilePtr in(cmsOpenProfileFromFile(path.string().c_str(), "r"));
    if (!in) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: lcms2 cannot read the ICC profile", path.string()));
    }
    ProfilePtr xyz(cmsCreateXYZProfile());
    cmsHTRANSFORM t = cmsCreateTransform(in.get(), TYPE_RGB_DBL, xyz.get(), TYPE_XYZ_DBL,
                                         INTENT_RELATIVE_COLORIMETRIC, cmsFLAGS_NOOPTIMIZE);
    if (t == nullptr) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: lcms2 cannot build a transform from the profile", path.string()));
    }
    const double maxCount = std::ldexp(1.0, bitDepth) - 1.0;
    std::vector<glm::dvec3> out;
    out.reserve(counts.size());
    for (const auto& c : counts) {
        const double rgb[3] = {c.x / maxCount, c.y / maxCount, c.z / maxCount};
        cmsCIEXYZ x{};
        cmsDoTransform(t, rgb, &x, 1);
        out.emplace_back(x.X, x.Y, x.Z);
    }
    cmsDeleteTransform(t);
    return out;
}

} // namespace replica::pipeline::display
