// The render profile: one recorded number naming the render path of the build that made a
// recording. Main keeps one render path, today's (kRenderProfile); a recording made with an
// older profile replays on it approximately (platform/cli/replay_compat.h compares the frames
// with what the recording holds of what was shown), and bit-exact replay of such a recording is
// promised by the build that made it (its package version). A profile newer than this build's
// is refused: this build cannot know how that recording was rendered.
#pragma once

#include <pipeline/base/expected.h>

namespace replica::pipeline::render {

// What a new run records ("render_profile"). Profiles 0 (switches recorded one by one) and 1 (the
// renderer before the switches) were older render paths; a recording without the key is profile
// 0. docs/rendering.md ("Render profile") says what changed from one to the next.
inline constexpr int kRenderProfile = 2;

// Whether this build renders profile 'number' bit for bit (it is kRenderProfile).
inline bool rendersExactly(int number)
{
    return number == kRenderProfile;
}

// An error naming this build's profile for a number above it (or below 0): a recording from a
// newer build, or a typo.
Expected<void> checkRenderProfile(int number);

} // namespace replica::pipeline::render
