#include "daemon/sim_turntable_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>
#include <vector>

namespace boxd {

namespace fs = std::filesystem;

namespace {

// Returns the child's exit status if it has exited, without waiting.
bool Exited(pid_t pid) {
    int status = 0;
    return waitpid(pid, &status, WNOHANG) == pid;
}

}  // namespace

fs::path CurrentExecutable() {
    std::error_code ec;
    fs::path p = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path("boxd") : p;
}

Result<std::unique_ptr<SimTurntableProcess>> SimTurntableProcess::Start(const fs::path& boxd_binary,
                                                                        int port,
                                                                        double speed_dps) {
    auto fail = [](const std::string& what) {
        return Error{"TURNTABLE_ERROR", "simulated turntable: " + what};
    };
    std::string dir_template = (fs::temp_directory_path() / "boxd-sim-XXXXXX").string();
    if (mkdtemp(dir_template.data()) == nullptr) return fail("cannot create a temporary folder");
    const fs::path dir = dir_template;
    const fs::path port_file = dir / "port";

    std::vector<std::string> args = {boxd_binary.string(),
                                     "sim-turntable",
                                     "--host",
                                     "127.0.0.1",
                                     "--port",
                                     std::to_string(port),
                                     "--speed-dps",
                                     std::to_string(speed_dps),
                                     "--port-file",
                                     port_file.string()};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    const pid_t parent = getpid();
    const pid_t pid = fork();
    if (pid < 0) return fail("fork failed");
    if (pid == 0) {
        // The child must not outlive the daemon, even when the daemon is killed with SIGKILL.
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() != parent) _exit(1);
        const int null_fd = open("/dev/null", O_RDWR);
        if (null_fd >= 0) {
            dup2(null_fd, 0);
            dup2(null_fd, 1);
        }
        // Start from default dispositions and an empty mask whatever the daemon set up.
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, nullptr);
        execv(argv[0], argv.data());
        _exit(127);
    }

    // Wait for the port file: the simulator writes it once it listens.
    int bound = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline) {
        std::ifstream in(port_file);
        if (in >> bound && bound > 0) break;
        if (Exited(pid)) {
            std::error_code ec;
            fs::remove_all(dir, ec);
            return fail("boxd sim-turntable exited at start (port " + std::to_string(port) +
                        " in use?)");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    std::unique_ptr<SimTurntableProcess> process(new SimTurntableProcess(pid, bound));
    if (bound <= 0) return fail("boxd sim-turntable did not start listening within 10 s");
    spdlog::info("simulated turntable: boxd sim-turntable (pid {}) on 127.0.0.1:{}", pid, bound);
    return process;
}

SimTurntableProcess::~SimTurntableProcess() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (std::chrono::steady_clock::now() < deadline) {
        if (Exited(pid_)) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
}

}  // namespace boxd
