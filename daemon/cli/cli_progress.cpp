#include "daemon/cli/cli_progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace boxd::cli {

namespace {

constexpr int kBarWidth = 24;

}  // namespace

Progress::Progress(std::string task, std::chrono::milliseconds quiet)
    : task_(std::move(task)),
      show_from_(std::chrono::steady_clock::now() + quiet),
      terminal_(isatty(STDERR_FILENO)) {}

Progress::~Progress() { Finish(); }

void Progress::Step(const std::string& step, int done, int total) {
    if (std::chrono::steady_clock::now() < show_from_) return;
    total = std::max(total, 1);
    done = std::clamp(done, 0, total);
    if (!terminal_) {
        std::fprintf(stderr, "boxd: %s: %s %d of %d\n", task_.c_str(), step.c_str(), done, total);
        return;
    }
    const int filled = done * kBarWidth / total;
    const std::string bar = std::string(static_cast<std::size_t>(filled), '#') +
                            std::string(static_cast<std::size_t>(kBarWidth - filled), '.');
    // \r and "erase line": the bar replaces itself.
    std::fprintf(stderr, "\r\033[K%s [%s] %s %d/%d", task_.c_str(), bar.c_str(), step.c_str(), done,
                 total);
    std::fflush(stderr);
    open_ = true;
}

void Progress::Finish() {
    if (!open_) return;
    std::fputc('\n', stderr);
    open_ = false;
}

}  // namespace boxd::cli
