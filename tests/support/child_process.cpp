#include "tests/support/child_process.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
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
    pid_ = fork();
    if (pid_ != 0) return;
    if (!log.empty()) {
        const int err = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
        const int null_fd = open("/dev/null", O_RDWR);
        dup2(null_fd, 0);
        dup2(null_fd, 1);
        dup2(err, 2);
    }
    for (const auto& e : env) putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
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

SimTurntableProcess::SimTurntableProcess(const std::vector<std::string>& extra_args) {
    std::vector<std::string> argv{BOXD_BINARY, "sim-turntable", "--port",
                                  "0",         "--port-file",   (dir_ / "port").string()};
    argv.insert(argv.end(), extra_args.begin(), extra_args.end());
    process_ = std::make_unique<ChildProcess>(argv);
    const auto deadline = Clock::now() + std::chrono::seconds(10);
    while (Clock::now() < deadline && process_->Running()) {
        std::ifstream in(dir_ / "port");
        if (in >> port_) break;
        port_ = 0;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
}

}  // namespace boxd::test
