#include "drivers/sim/sim_turntable_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <thread>

namespace boxd {

namespace fs = std::filesystem;

namespace {

Error LaunchError(const std::string& what) {
    return Error{ErrorCode::kTurntableError, "simulated turntable: " + what};
}

}  // namespace

fs::path CurrentExecutable() {
    std::error_code ec;
    fs::path p = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path("boxd") : p;
}

Result<std::unique_ptr<SimTurntableProcess>> SimTurntableProcess::Start(
    const SimTurntableLaunch& launch) {
    std::string dir_template = (fs::temp_directory_path() / "boxd-sim-XXXXXX").string();
    if (mkdtemp(dir_template.data()) == nullptr) {
        return LaunchError("cannot create a temporary folder");
    }
    const fs::path dir = dir_template;
    const fs::path port_file = dir / "port";
    auto cleanup = [&dir] {
        std::error_code ec;
        fs::remove_all(dir, ec);
    };

    // Everything the child needs is prepared before fork: it only redirects and execs.
    std::vector<std::string> args = {
        launch.binary.empty() ? CurrentExecutable().string() : launch.binary.string(),
        "sim-turntable",
        "--host",
        "127.0.0.1",
        "--port",
        std::to_string(launch.port),
        "--port-file",
        port_file.string(),
        "--exit-with-parent"};
    args.insert(args.end(), launch.args.begin(), launch.args.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int null_fd = open("/dev/null", O_RDWR | O_CLOEXEC);
    const int log_fd = launch.log.empty() ? -1
                                          : open(launch.log.c_str(),
                                                 O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);

    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid == 0) {
        // The child must not outlive this process, even when it is killed with SIGKILL:
        // --exit-with-parent makes it watch its parent. (PR_SET_PDEATHSIG would fire when the
        // forking *thread* ends, and devices are opened from worker threads.)
        if (getppid() != parent) _exit(1);
        if (null_fd >= 0) {
            dup2(null_fd, 0);
            dup2(null_fd, 1);
        }
        if (log_fd >= 0) dup2(log_fd, 2);
        // Start from default dispositions and an empty mask whatever the parent set up.
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, nullptr);
        execv(argv[0], argv.data());
        _exit(127);
    }
    if (null_fd >= 0) close(null_fd);
    if (log_fd >= 0) close(log_fd);
    if (pid < 0) {
        cleanup();
        return LaunchError("fork failed");
    }
    std::unique_ptr<SimTurntableProcess> process(new SimTurntableProcess(pid, 0));

    const Status listening = process->WaitForPort(port_file, launch);
    cleanup();
    if (!listening) return listening.error();
    spdlog::info("simulated turntable: boxd sim-turntable (pid {}) on 127.0.0.1:{}", pid,
                 process->port_);
    return process;
}

Status SimTurntableProcess::WaitForPort(const fs::path& port_file,
                                        const SimTurntableLaunch& launch) {
    // The simulator writes the port file once it listens: no race for a free port.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline) {
        std::ifstream in(port_file);
        if (int bound = 0; in >> bound && bound > 0) {
            port_ = bound;
            return OkStatus();
        }
        if (launch.cancel != nullptr && launch.cancel->load()) {
            return Error{ErrorCode::kAborted, "simulated turntable: its start was abandoned"};
        }
        if (!Running()) {
            return LaunchError("boxd sim-turntable exited at start (port " +
                               std::to_string(launch.port) + " in use?)");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return LaunchError("boxd sim-turntable did not start listening within 10 s");
}

bool SimTurntableProcess::Reaped() {
    if (exit_code_ >= 0) return true;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) != pid_) return false;
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return true;
}

bool SimTurntableProcess::Running() { return !Reaped(); }

void SimTurntableProcess::Signal(int signal) const {
    if (exit_code_ < 0) kill(pid_, signal);
}

int SimTurntableProcess::Terminate(std::chrono::milliseconds grace) {
    if (Reaped()) return exit_code_;
    kill(pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + grace;
    while (std::chrono::steady_clock::now() < deadline) {
        if (Reaped()) return exit_code_;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return exit_code_;
}

SimTurntableProcess::~SimTurntableProcess() { Terminate(); }

}  // namespace boxd
