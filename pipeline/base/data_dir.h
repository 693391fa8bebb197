// Where Replica's shipped data (spectra, booth lights, scenes, display profiles) is found.
#pragma once

#include <filesystem>

namespace replica {

// In this order: $REPLICA_DATA_DIR if set; ../share/replica next to the running binary when it
// is there (an installed binary, under any prefix, also one unpacked from the .deb); the data/
// folder of the source tree this binary was built from (the build tree); the install data
// folder configured at build time.
std::filesystem::path dataDir();

} // namespace replica
