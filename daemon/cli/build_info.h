#pragma once
// What `boxd --version` says: the release, the commit it was built from and the build type. The
// commit is read from git at every build (daemon/cli/build_info.cmake), so a binary never names
// an older commit than its own.

namespace boxd::cli {

// The project's version ("0.1.0").
const char* BuildVersion();
// The commit ("b3d8619a2f4c", "-dirty" when the tree had changes; "unknown" outside git).
const char* BuildCommit();
// CMAKE_BUILD_TYPE ("Release"; "unspecified" when none was set).
const char* BuildType();

}  // namespace boxd::cli
