// Reading a sysfs attribute (an IIO value, a USB device's ids and serial, a HID device's uevent and
// report descriptor): opened without waiting, answered within kSysfsWaitMs in all, at most a given
// number of bytes. A FIFO, a device or a file that never answers in its place is an error in
// bounded time, never a read that holds the device's thread (and SIGTERM) without end; /dev/zero
// or a large file is an error past the limit; a directory an error.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include <pipeline/base/expected.h>

namespace replica::hal {

constexpr int kSysfsWaitMs = 200;

// How much of the attribute is wanted: its first line (a value: reading stops at the first
// newline, which a sysfs attribute gives in its first read), or the whole file up to its end.
enum class SysfsRead { FirstLine, Whole };

// The attribute's bytes (FirstLine: without the newline), at most maxBytes; more is an error.
Expected<std::string>
readSysfsFile(const std::filesystem::path& file, std::size_t maxBytes, SysfsRead what);

} // namespace replica::hal
