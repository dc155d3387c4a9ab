// What every subcommand shares: the one error line and exit code, and the logger.
#include <malloc.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>

#include "daemon/cli/cli.h"

namespace boxd::cli {

int Fail(const Error& error) {
    std::string line = error.message;
    for (char& c : line) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    std::fprintf(stderr, "boxd: error: %s: %s\n", ErrorCodeName(error.code), line.c_str());
    return ExitCodeOf(error.code);
}

Status CheckOutFolder(const std::filesystem::path& out, bool force) {
    std::error_code ec;
    if (force || !std::filesystem::exists(out, ec) ||
        (std::filesystem::is_directory(out, ec) && std::filesystem::is_empty(out, ec))) {
        return OkStatus();
    }
    return Error{ErrorCode::kInvalidInput,
                 "--out " + out.string() +
                     ": exists and is not an empty folder (use --force to write into it)"};
}

void SetupLogging() {
    auto logger = spdlog::stderr_color_mt("boxd");
    spdlog::set_default_logger(logger);
    spdlog::set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ %v");
    const char* level = std::getenv("BOXD_LOG_LEVEL");
    spdlog::set_level(level ? spdlog::level::from_str(level) : spdlog::level::info);
}

void KeepFreedBuffers() {
    mallopt(M_MMAP_THRESHOLD, 256 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

}  // namespace boxd::cli
