// The spectrometer's samples on /hal/spectrometer: JSON payload, schema and codec.
#include <fmt/format.h>

#include <recordings/codec_json.h>

namespace replica::recordings {

std::optional<std::string> encodeSpectrum(const hal::SpectrumSample& s)
{
    if (!finite(s.wavelengthCoeffs) || !finite(s.nonlinearityCoeffs)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs},
                {"seq", s.sequence},
                {"integration_time_us", s.integrationTimeUs},
                {"counts", s.counts},
                {"wavelength_coeffs", s.wavelengthCoeffs},
                {"nonlinearity_coeffs", s.nonlinearityCoeffs},
                {"saturated", s.saturated}}
            .dump();
}

hal::SpectrumSample decodeSpectrum(const json& j)
{
    hal::SpectrumSample s;
    s.timestampNs = integerField<std::int64_t>(j, "t");
    s.sequence = integerField<std::uint32_t>(j, "seq");
    s.integrationTimeUs = integerField<std::uint32_t>(j, "integration_time_us");
    if (j.at("counts").size() > kMaxSpectrumCounts) {
        throw std::out_of_range(fmt::format("{} counts; a spectrometer has at most {} pixels",
                                            j.at("counts").size(), kMaxSpectrumCounts));
    }
    // Each count as the detector gives it, 0..65535: get<uint16_t>() would wrap 70000 to 4464
    // and -1 to 65535, a light the instrument never saw.
    const json& counts = j.at("counts");
    if (!counts.is_array()) {
        throw std::out_of_range(
                fmt::format("counts: expected an array, found {}", counts.type_name()));
    }
    s.counts.reserve(counts.size());
    for (std::size_t i = 0; i < counts.size(); ++i) {
        s.counts.push_back(integerValue<std::uint16_t>(counts[i], fmt::format("counts[{}]", i)));
    }
    s.wavelengthCoeffs = j.at("wavelength_coeffs");
    s.nonlinearityCoeffs = j.at("nonlinearity_coeffs");
    s.saturated = j.at("saturated");
    return s;
}

std::pair<std::string, std::string> spectrumSchema()
{
    return {"replica.SpectrometerSample",
            schemaText("replica.SpectrometerSample",
                       "One raw spectrum with the device calibration needed to convert it",
                       std::string(kTimeSeqProps) + R"(,
    "integration_time_us": {"type": "integer"},
    "counts": {"type": "array", "items": {"type": "integer", "minimum": 0, "maximum": 65535},
      "description": "raw counts, pixel 0 first"},
    "wavelength_coeffs": {"type": "array", "items": {"type": "number"}, "minItems": 4,
      "maxItems": 4, "description": "wavelength (nm) of pixel p = c0 + c1 p + c2 p^2 + c3 p^3"},
    "nonlinearity_coeffs": {"type": "array", "items": {"type": "number"}, "minItems": 8,
      "maxItems": 8, "description": "counts correction polynomial, order 0..7"},
    "saturated": {"type": "boolean"})",
                       R"("t", "seq", "integration_time_us", "counts", "wavelength_coeffs",
    "nonlinearity_coeffs", "saturated")")};
}

SampleCodec<hal::SpectrumSample> spectrumCodec()
{
    SampleCodec<hal::SpectrumSample> c;
    c.encode = encodeSpectrum;
    c.decode = decodeSpectrum;
    return c;
}

} // namespace replica::recordings
