// libFuzzer target: the session loader (SPEC section 3), session.json and a 16-bit PNG.
// An input is the text of session.json, a NUL byte, then the bytes of the file `f.png`, which
// the seeds' session.json names as its frames. LoadSession must return a session or an
// INVALID_SESSION error: never crash, hang, or allocate without bound.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "pipeline/io/session_io.h"
#include "tests/fuzz/fuzz_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const std::size_t nul = input.find('\0');
    const std::string_view json = input.substr(0, nul);
    const std::string_view png = nul == std::string_view::npos ? "" : input.substr(nul + 1);

    const auto& dir = boxd::fuzz::ScratchDir();
    boxd::fuzz::WriteFile(dir / "session.json", json);
    boxd::fuzz::WriteFile(dir / "f.png", png);
    const auto session = boxd::LoadSession(dir);
    if (!session && session.error().code != boxd::ErrorCode::kInvalidSession) __builtin_trap();
    return 0;
}
