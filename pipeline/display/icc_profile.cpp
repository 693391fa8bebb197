// ICC v2.4 or v4.3 display profile through Little CMS 2.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <glm/matrix.hpp>
#include <lcms2.h>

#include <pipeline/base/output_file.h>
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

namespace {

// The tone curve of channel c as 'samples' 16-bit entries (an exact curve for 8-bit pixels when
// samples is 256), or 4096 float samples when samples is 0.
std::unique_ptr<cmsToneCurve, CurveFree>
trcCurve(const DisplayModel& model, int c, double bc, int samples)
{
    const int n = samples > 1 ? samples : 4096;
    std::vector<double> v(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double d = model.maxCount() * static_cast<double>(i) / (n - 1);
        v[static_cast<std::size_t>(i)] = std::clamp((model.tone[c](d) + bc) / (1.0 + bc), 0.0, 1.0);
    }
    if (samples > 1) {
        std::vector<cmsUInt16Number> t(v.size());
        std::transform(v.begin(), v.end(), t.begin(), [](double x) {
            return static_cast<cmsUInt16Number>(std::lround(x * 65535.0));
        });
        return std::unique_ptr<cmsToneCurve, CurveFree>(
                cmsBuildTabulatedToneCurve16(nullptr, static_cast<cmsUInt32Number>(n), t.data()));
    }
    std::vector<cmsFloat32Number> f(v.begin(), v.end());
    return std::unique_ptr<cmsToneCurve, CurveFree>(
            cmsBuildTabulatedToneCurveFloat(nullptr, static_cast<cmsUInt32Number>(n), f.data()));
}

// The profile of the model (writeIccProfile's header comment); 'where' names it in errors.
Expected<ProfilePtr> buildProfile(const DisplayModel& model,
                                  IccWriteReport& report,
                                  int samples,
                                  IccVersion version,
                                  const std::string& where)
{
    report.crosstalkOmitted = model.hasCrosstalk();
    const glm::dvec3 white = model.whiteXyz();
    if (!(white.y > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the model's white has no luminance", where));
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
    const cmsCIEXYZ mediaWhite{white.x / white.y, 1.0, white.z / white.y};
    cmsHPROFILE h = cmsCreateProfilePlaceholder(nullptr);
    if (h == nullptr) {
        return makeError(ErrorCode::Io, "lcms2: cannot create a profile");
    }
    ProfilePtr guard(h);
    const bool v4 = version == IccVersion::V4_3;
    cmsSetProfileVersion(h, v4 ? 4.3 : 2.4);
    cmsSetDeviceClass(h, cmsSigDisplayClass);
    cmsSetColorSpace(h, cmsSigRgbData);
    cmsSetPCS(h, cmsSigXYZData);
    cmsSetHeaderRenderingIntent(h, INTENT_RELATIVE_COLORIMETRIC);
    bool ok = writeText(h, cmsSigProfileDescriptionTag, model.name) &&
              writeText(h, cmsSigCopyrightTag, "No copyright; written by replica display fit") &&
              cmsWriteTag(h, cmsSigMediaWhitePointTag, v4 ? cmsD50_XYZ() : &mediaWhite) != 0 &&
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
    const cmsTagSignature trcTags[3] = {cmsSigRedTRCTag, cmsSigGreenTRCTag, cmsSigBlueTRCTag};
    for (int c = 0; ok && c < 3; ++c) {
        const auto curve = trcCurve(model, c, b[c], samples);
        ok = curve != nullptr && cmsWriteTag(h, trcTags[c], curve.get()) != 0;
    }
    if (!ok) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: lcms2 could not build the profile's tags", where));
    }
    return guard;
}

} // namespace

Expected<IccWriteReport>
writeIccProfile(const DisplayModel& model, const std::filesystem::path& path, IccVersion version)
{
    IccWriteReport report;
    // TRCs sampled at 4096 points over the count range (the curv tag holds 16-bit values).
    auto h = buildProfile(model, report, 0, version, path.string());
    if (!h) {
        return tl::unexpected(h.error());
    }
    cmsUInt32Number size = 0;
    std::string bytes;
    if (cmsSaveProfileToMem(h->get(), nullptr, &size) != 0 && size > 0) {
        bytes.resize(size);
        if (cmsSaveProfileToMem(h->get(), bytes.data(), &size) == 0) {
            size = 0;
        }
    }
    if (size == 0) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: lcms2 cannot serialise the ICC profile", path.string()));
    }
    bytes.resize(size);
    // Written the one safe way (pipeline/base/output_file.h).
    if (auto ok = writeOutputFile(path, bytes, "ICC profile"); !ok) {
        return tl::unexpected(ok.error());
    }
    return report;
}

Expected<std::vector<std::uint8_t>>
iccProfileBytes(const DisplayModel& model, int trcSamples, IccVersion version)
{
    IccWriteReport report;
    auto h = buildProfile(model, report, std::max(trcSamples, 2), version, model.name);
    if (!h) {
        return tl::unexpected(h.error());
    }
    cmsUInt32Number size = 0;
    if (cmsSaveProfileToMem(h->get(), nullptr, &size) == 0 || size == 0) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: lcms2 cannot serialise the ICC profile", model.name));
    }
    std::vector<std::uint8_t> out(size);
    if (cmsSaveProfileToMem(h->get(), out.data(), &size) == 0) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: lcms2 cannot serialise the ICC profile", model.name));
    }
    out.resize(size);
    // The header's creation date (bytes 24-35, six big-endian 16-bit numbers) is the moment lcms2
    // built the profile; the model has no date of its own. A fixed one (1970-01-01 00:00:00) keeps
    // the bytes, and so every PNG that embeds them, the same from run to run.
    if (out.size() >= 36) {
        const std::uint16_t date[6] = {1970, 1, 1, 0, 0, 0};
        for (std::size_t i = 0; i < 6; ++i) {
            out[24 + 2 * i] = static_cast<std::uint8_t>(date[i] >> 8);
            out[25 + 2 * i] = static_cast<std::uint8_t>(date[i] & 0xff);
        }
    }
    return out;
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
    if (const auto* wtpt =
                static_cast<const cmsCIEXYZ*>(cmsReadTag(in.get(), cmsSigMediaWhitePointTag));
        wtpt != nullptr) {
        info.mediaWhite = glm::dvec3(wtpt->X, wtpt->Y, wtpt->Z);
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
