// Where Replica's shipped data (spectra, booth lights, scenes, display profiles) is found.
#pragma once

#include <cstdlib>
#include <filesystem>

namespace replica {

// $REPLICA_DATA_DIR if set, else the data/ folder of the source tree this binary was built from.
inline std::filesystem::path dataDir()
{
    if (const char* env = std::getenv("REPLICA_DATA_DIR"); env != nullptr && *env != '\0') {
        return env;
    }
    return REPLICA_SOURCE_DATA_DIR;
}

} // namespace replica
