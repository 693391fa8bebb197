// Colour space and time chunks of shown frames' PNGs (see the header).
#include <ctime>

#include <fmt/format.h>

#include <platform/image/png_metadata.h>

namespace replica::platform {

namespace {

constexpr std::int64_t kPngNsPerS = 1'000'000'000;

std::int64_t floorDivNs(std::int64_t a, std::int64_t b)
{
    return a / b - ((a % b != 0) && ((a < 0) != (b < 0)) ? 1 : 0);
}

// "2026-12-06T14:32:05.250Z".
std::string pngIsoUtc(std::int64_t unixNs)
{
    const std::time_t secs = static_cast<std::time_t>(floorDivNs(unixNs, kPngNsPerS));
    std::tm tm{};
    if (::gmtime_r(&secs, &tm) == nullptr) {
        return "unknown";
    }
    return fmt::format("{:04d}-{:02d}-{:02d}T{:02d}:{:02d}:{:02d}.{:03d}Z", tm.tm_year + 1900,
                       tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                       static_cast<int>(floorDivNs(unixNs, 1'000'000) % 1000));
}

} // namespace

std::string pngKeyword(const std::string& s)
{
    std::string out;
    for (const char c : s) {
        const bool printable = c > ' ' && c < 127;
        if (printable) {
            out += c;
        } else if (!out.empty() && out.back() != ' ') {
            out += ' ';
        }
        if (out.size() == 79) {
            break;
        }
    }
    while (!out.empty() && out.back() == ' ') {
        out.pop_back();
    }
    return out.empty() ? std::string("profile") : out;
}

PngMetadata shownFrameMetadata(const std::vector<std::uint8_t>& icc,
                               const std::string& profileName,
                               std::int64_t wallStartNs,
                               std::int64_t tickNs,
                               std::uint64_t frameIndex)
{
    PngMetadata m;
    m.icc = icc;
    m.srgb = icc.empty();
    m.iccName = pngKeyword(profileName);
    std::string frame = fmt::format("frame {}, session second {}", frameIndex,
                                    static_cast<double>(tickNs) / 1e9);
    if (wallStartNs > 0) {
        m.unixNs = wallStartNs + tickNs;
        frame += fmt::format(", recording started {}", pngIsoUtc(wallStartNs));
    }
    m.text.emplace_back("Replica frame", frame);
    m.text.emplace_back("Software", "replica");
    return m;
}

PngChunks::PngChunks(const PngMetadata* meta) : meta_(meta)
{
    if (meta_ == nullptr) {
        return;
    }
    iccName_ = pngKeyword(meta_->iccName);
    if (meta_->unixNs) {
        const auto secs = static_cast<std::time_t>(floorDivNs(*meta_->unixNs, kPngNsPerS));
        std::tm tm{};
        if (::gmtime_r(&secs, &tm) != nullptr) {
            time_.year = static_cast<png_uint_16>(tm.tm_year + 1900);
            time_.month = static_cast<png_byte>(tm.tm_mon + 1);
            time_.day = static_cast<png_byte>(tm.tm_mday);
            time_.hour = static_cast<png_byte>(tm.tm_hour);
            time_.minute = static_cast<png_byte>(tm.tm_min);
            time_.second = static_cast<png_byte>(tm.tm_sec);
            hasTime_ = true;
            strings_.emplace_back("Creation Time");
            strings_.push_back(pngIsoUtc(*meta_->unixNs));
        }
    }
    for (const auto& [key, value] : meta_->text) {
        strings_.push_back(pngKeyword(key));
        strings_.push_back(value);
    }
    // The strings no longer move: point the png_text entries at them.
    for (std::size_t i = 0; i + 1 < strings_.size(); i += 2) {
        png_text t{};
        t.compression = PNG_TEXT_COMPRESSION_NONE;
        t.key = strings_[i].data();
        t.text = strings_[i + 1].data();
        t.text_length = strings_[i + 1].size();
        text_.push_back(t);
    }
}

void PngChunks::apply(png_structp png, png_infop info) const
{
    if (meta_ == nullptr) {
        return;
    }
    if (!meta_->icc.empty()) {
        png_set_iCCP(png, info, iccName_.c_str(), PNG_COMPRESSION_TYPE_BASE, meta_->icc.data(),
                     static_cast<png_uint_32>(meta_->icc.size()));
    } else if (meta_->srgb) {
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    }
    if (hasTime_) {
        png_set_tIME(png, info, &time_);
    }
    if (!text_.empty()) {
        png_set_text(png, info, text_.data(), static_cast<int>(text_.size()));
    }
}

} // namespace replica::platform
