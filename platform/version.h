// The program's version and the git commit it was built from (fixed when CMake configured).
#pragma once

#include <string>

namespace replica::platform {

// The package version: "0.1.0+git1234.g5237685c1a2b" (CMakeLists.txt says how it is made).
const char* versionNumber();
// 'git describe --always --dirty' of the source tree, or "unknown-commit" outside a git checkout.
const char* gitCommit();
// "replica 0.1.0+git1234.g5237685c1a2b (git 5237685c1a2b)": what --version prints and recordings
// store.
std::string versionString();

} // namespace replica::platform
