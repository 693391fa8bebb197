// The data folder's lookup (pipeline/base/data_dir.h).
#include <cstdlib>
#include <system_error>

#include <pipeline/base/data_dir.h>

namespace replica {

std::filesystem::path dataDir()
{
    if (const char* env = std::getenv("REPLICA_DATA_DIR"); env != nullptr && *env != '\0') {
        return env;
    }
    static const std::filesystem::path found = [] {
        std::error_code ec;
        const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
        if (!ec) {
            const auto installed = exe.parent_path().parent_path() / "share" / "replica";
            if (std::filesystem::is_directory(installed / "spectra", ec)) {
                return installed;
            }
        }
        const std::filesystem::path source = REPLICA_SOURCE_DATA_DIR;
        if (std::filesystem::is_directory(source, ec)) {
            return source;
        }
        return std::filesystem::path(REPLICA_INSTALL_DATA_DIR);
    }();
    return found;
}

} // namespace replica
