#pragma once
// Input and output: Reading and writing sessions in the boxd.session/1 folder format (SPEC section
// 3).

#include <filesystem>

#include "pipeline/core/result.h"
#include "pipeline/io/session.h"

namespace boxd {

// Returns the session in `dir` with all frames loaded, or an INVALID_SESSION error naming the
// file and the field that break the format.
Result<Session> LoadSession(const std::filesystem::path& dir);

// Returns the session in `dir` without its frames (their paths only), or the error LoadSession
// gives for a broken session.json.
Result<Session> LoadSessionHeader(const std::filesystem::path& dir);

// Returns the frames of pose `pose` of `header` (loaded from `dir`), or the error LoadSession
// gives for the first of them that cannot be read.
Result<std::vector<DepthImage>> LoadPoseFrames(const std::filesystem::path& dir,
                                               const Session& header, std::size_t pose);

// Writes `session` (session.json and every frame as a 16-bit PNG) into `dir`, creating it.
// Frames are written at their `frame_paths`; a pose without paths gets the standard ones.
Status WriteSession(const Session& session, const std::filesystem::path& dir);

}  // namespace boxd
