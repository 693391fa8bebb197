// Error and Expected<T>: the one vocabulary for reporting bad input that every layer may include.
#pragma once

#include <string>
#include <utility>

#include <tl/expected.hpp>

namespace replica {

enum class ErrorCode {
    InvalidArgument, // a value given by a person or a file is out of range or malformed
    NotFound,        // a file, device or named item does not exist
    Io,              // reading or writing failed
    Corrupt,         // a file exists but its contents fail a check
    Unsupported,     // a valid request this build or device cannot do
    DeviceFailure,   // a device was found but misbehaved
};

// One human sentence that names the thing and, where there is one, the fix.
struct Error {
    ErrorCode code = ErrorCode::InvalidArgument;
    std::string message;
};

template <typename T>
using Expected = tl::expected<T, Error>;

inline tl::unexpected<Error> makeError(ErrorCode code, std::string message)
{
    return tl::unexpected<Error>(Error{code, std::move(message)});
}

} // namespace replica
