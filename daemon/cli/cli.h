#pragma once
// The boxd command line: one subcommand per file (cli_<name>.cpp), registered by main.cpp.

#include <functional>
#include <string>

#include "pipeline/result.h"

namespace CLI {
class App;
}

namespace boxd::cli {

// Exit codes of SPEC section 4 that are not an error's: an error's is ExitCodeOf(its code).
inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitNoDim = 3;  // measured, status no_dim, the JSON is on stdout

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

// Prints "boxd: error: CODE: message" as one line on stderr and returns ExitCodeOf(error.code):
// the one way a subcommand ends on an error.
int Fail(const Error& error);

// Routes logs to stderr; the level comes from BOXD_LOG_LEVEL (trace..critical, default info).
void SetupLogging();

// For a one-shot measurement: keeps freed memory in the process's heap. A session's frames and
// depth maps are hundreds of buffers of 0.3-1.2 MB; glibc would map each from the kernel and
// return it when freed, so every one of them would cost its page faults anew.
void KeepFreedBuffers();

}  // namespace boxd::cli
