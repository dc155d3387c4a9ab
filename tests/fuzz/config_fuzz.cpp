// libFuzzer target: the config loader of `boxd serve` (YAML: server, storage, turntable, camera,
// capture, calibration, measurement). An input is the text of the config file. LoadServeConfig must
// return a config or an INVALID_INPUT error naming the key: never crash or hang.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "daemon/service/serve_config.h"
#include "tests/fuzz/fuzz_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto file = boxd::fuzz::ScratchDir() / "boxd.yaml";
    boxd::fuzz::WriteFile(file, std::string_view(reinterpret_cast<const char*>(data), size));
    const auto config = boxd::LoadServeConfig(file, {});
    if (!config && config.error().code != boxd::ErrorCode::kInvalidInput) __builtin_trap();
    return 0;
}
