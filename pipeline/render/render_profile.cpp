#include <fmt/format.h>

#include <pipeline/render/render_profile.h>

namespace replica::pipeline::render {

Expected<void> checkRenderProfile(int number)
{
    if (number >= 0 && number <= kRenderProfile) {
        return {};
    }
    return makeError(ErrorCode::Unsupported,
                     fmt::format("render profile {} is newer than this build's ({}); replay the "
                                 "recording with the build that made it or a newer one",
                                 number, kRenderProfile));
}

} // namespace replica::pipeline::render
