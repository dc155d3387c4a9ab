#pragma once
// The boxd command line: one subcommand per file (cli_<name>.cpp), registered by main.cpp.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "pipeline/core/result.h"

namespace CLI {
class App;
}

namespace boxd::cli {

// Exit codes of SPEC section 4 that are not an error's: an error's is ExitCodeOf(its code).
inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitNoDim = 3;  // measured, status no_dim, the JSON is on stdout
// boxd verify: a stored record was changed or deleted (an addition to SPEC section 4).
inline constexpr int kExitVerifyFailed = 4;

// Set by the chosen subcommand's callback; main() runs it after parsing.
using Runner = std::function<int()>;

void AddServe(CLI::App& app, Runner& run);
void AddMeasure(CLI::App& app, Runner& run);
void AddCalibrate(CLI::App& app, Runner& run);
void AddRecord(CLI::App& app, Runner& run);
void AddSynth(CLI::App& app, Runner& run);
void AddSimTurntable(CLI::App& app, Runner& run);
void AddDevices(CLI::App& app, Runner& run);
void AddBenchMeasure(CLI::App& app, Runner& run);
void AddVerify(CLI::App& app, Runner& run);
void AddExport(CLI::App& app, Runner& run);
void AddImportDump(CLI::App& app, Runner& run);

// Returns "boxd 0.1.0 (commit b3d8619a2f4c, Release build)".
std::string VersionText();

// Returns the error for an unknown command or an unknown long option of the command in `argv`
// (naming the nearest valid one), or nothing: checked before parsing, so that a slip is named as
// such rather than as a missing required option.
std::optional<Error> CheckArguments(const CLI::App& app, int argc, char** argv);

// Prints "boxd: error: CODE: message" as one line on stderr and returns ExitCodeOf(error.code):
// the one way a subcommand ends on an error.
int Fail(const Error& error);

// Returns Ok when `out` may receive a session: absent, an empty folder, or anything with `force`;
// else INVALID_INPUT naming it.
Status CheckOutFolder(const std::filesystem::path& out, bool force);

// Routes logs to stderr; the level comes from BOXD_LOG_LEVEL (trace..critical, default info).
void SetupLogging();

// For a one-shot measurement: keeps freed memory in the process's heap. A session's frames and
// depth maps are hundreds of buffers of 0.3-1.2 MB; glibc would map each from the kernel and
// return it when freed, so every one of them would cost its page faults anew.
void KeepFreedBuffers();

}  // namespace boxd::cli
