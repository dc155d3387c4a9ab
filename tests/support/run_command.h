#pragma once
// Runs the real boxd binary (or any command) as a child process and captures what it prints.

#include <string>
#include <vector>

namespace boxd::test {

struct CommandOutput {
    int exit_code = -1;
    std::string out;  // stdout
    std::string err;  // stderr
};

// Returns the exit code, stdout and stderr of `argv` run to completion.
CommandOutput RunCommand(const std::vector<std::string>& argv);

// Runs the boxd binary under test with `args`.
CommandOutput RunBoxd(const std::vector<std::string>& args);

}  // namespace boxd::test
