#include "tests/support/child_process.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string_view>
#include <thread>

namespace boxd::test {

using Clock = std::chrono::steady_clock;

int FreePort() {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
    socklen_t len = sizeof(addr);
    getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    close(fd);
    return ntohs(addr.sin_port);
}

std::string ReadText(const std::filesystem::path& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log,
                           const std::vector<std::string>& env) {
    // Everything the child needs is built before fork: between fork and exec only
    // async-signal-safe calls are allowed (the test process may have other threads).
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    std::vector<std::string> names;
    for (const auto& e : env) names.push_back(e.substr(0, e.find('=') + 1));
    std::vector<char*> envp;
    for (char** e = environ; *e; ++e) {
        const std::string_view entry(*e);
        bool replaced = false;
        for (const auto& n : names) replaced = replaced || entry.rfind(n, 0) == 0;
        if (!replaced) envp.push_back(*e);
    }
    for (const auto& e : env) envp.push_back(const_cast<char*>(e.c_str()));
    envp.push_back(nullptr);
    const int log_fd =
        log.empty() ? -1 : open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    const int null_fd = log.empty() ? -1 : open("/dev/null", O_RDWR | O_CLOEXEC);
    const pid_t parent = getpid();

    pid_ = fork();
    if (pid_ == 0) {
        // Die with the test: a test killed on timeout must not leave a daemon running.
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent) _exit(127);
        if (log_fd >= 0 && null_fd >= 0) {  // dup2 clears close-on-exec on the copies
            dup2(null_fd, 0);
            dup2(null_fd, 1);
            dup2(log_fd, 2);
        }
        execvpe(args[0], args.data(), envp.data());
        _exit(127);
    }
    if (log_fd >= 0) close(log_fd);
    if (null_fd >= 0) close(null_fd);
    if (pid_ < 0) ADD_FAILURE() << "fork failed for " << argv.front();
}

ChildProcess::~ChildProcess() { Terminate(); }

void ChildProcess::Reap(int status) {
    exited_ = true;
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool ChildProcess::Running() {
    if (exited_ || pid_ <= 0) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) Reap(status);
    return !exited_;
}

void ChildProcess::Signal(int sig) {
    if (Running()) kill(pid_, sig);
}

std::optional<int> ChildProcess::WaitExit(std::chrono::milliseconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (Running()) {
        if (Clock::now() >= deadline) return std::nullopt;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return exit_code_;
}

int ChildProcess::Terminate(std::chrono::milliseconds grace) {
    if (pid_ <= 0) return -1;
    if (!Running()) return exit_code_;
    kill(pid_, SIGTERM);
    if (WaitExit(grace)) return exit_code_;
    kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
    Reap(status);
    return exit_code_;
}

SimTurntableProcess::SimTurntableProcess(const std::vector<std::string>& extra_args,
                                         const std::filesystem::path& log) {
    auto started = boxd::SimTurntableProcess::Start({BOXD_BINARY, 0, extra_args, log});
    EXPECT_TRUE(started.ok()) << started.error().message;
    if (started) process_ = std::move(*started);
}

}  // namespace boxd::test
