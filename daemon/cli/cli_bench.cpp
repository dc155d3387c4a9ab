// boxd bench-measure: times the measurement pipeline on one session (the figures behind the
// speed targets): the process's start-up, the session's load (PNG decode), then the median,
// min and max processing wall time over N runs with each stage's median, the poses used, and
// peak RSS. --repeat-to N makes the session a disagreeing one of N poses for the scaling
// figure: its poses repeated in turn under N evenly spaced angles, so that the views contradict
// the table's angles and one another.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "daemon/cli/cli.h"
#include "pipeline/io/session_io.h"
#include "pipeline/measure_pipeline.h"

namespace boxd::cli {

namespace {

struct BenchOptions {
    std::string session;
    int runs = 5;
    int threads = 2;
    int repeat_to = 0;
};

using Clock = std::chrono::steady_clock;

double Median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

double MsSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Returns the median wall time of starting this binary and letting it exit at once
// (`boxd --help`: loading its shared libraries and static initialisation), over 5 starts, or
// a negative number when it cannot be started.
double StartupMs() {
    std::vector<double> ms;
    for (int i = 0; i < 5; ++i) {
        const auto t0 = Clock::now();
        const pid_t pid = ::fork();
        if (pid < 0) return -1.0;
        if (pid == 0) {
            const int null = ::open("/dev/null", O_WRONLY);
            if (null >= 0) ::dup2(null, STDOUT_FILENO);
            ::execl("/proc/self/exe", "boxd", "--help", static_cast<char*>(nullptr));
            ::_exit(127);
        }
        int status = 0;
        ::waitpid(pid, &status, 0);
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return -1.0;
        ms.push_back(MsSince(t0));
    }
    return Median(ms);
}

// Makes `session` one of `poses` poses: its own poses in turn, at evenly spaced angles.
void RepeatPoses(Session& session, int poses) {
    const std::vector<SessionPose> own = std::move(session.poses);
    session.poses.clear();
    for (int k = 0; k < poses; ++k) {
        SessionPose pose = own[static_cast<std::size_t>(k) % own.size()];
        pose.angle_deg = 360.0 * k / poses;
        session.poses.push_back(std::move(pose));
    }
}

double CpuSeconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int RunBench(const BenchOptions& opt) {
    KeepFreedBuffers();
    const double startup_ms = StartupMs();
    const auto t0 = Clock::now();
    auto session = LoadSession(opt.session);
    if (!session) return Fail(session.error());
    const double load_ms = MsSince(t0);
    const std::size_t frames = session->poses.empty() ? 0 : session->poses[0].frames.size();
    if (opt.repeat_to > 0) RepeatPoses(*session, opt.repeat_to);
    MeasureConfig config;
    config.threads = opt.threads;
    config.registration.threads = opt.threads;
    config.box_fit.threads = opt.threads;
    config.envelope.threads = opt.threads;
    std::vector<double> wall;
    std::map<std::string, std::vector<double>> stages;
    std::string status;
    int poses_used = 0;
    const double cpu0 = CpuSeconds();
    for (int i = 0; i < opt.runs; ++i) {
        const auto a = Clock::now();
        auto out = MeasureSession(*session, config, BoxMethod::kFootprint, SteadyClockMs());
        wall.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
        if (!out) return Fail(out.error());
        status = StatusName(out->result.status);
        if (out->result.reason)
            status += " " + std::string(ErrorCodeName(out->result.reason->code));
        poses_used = out->result.quality.poses;
        for (const auto& [name, ms] : out->result.timing_ms) stages[name].push_back(ms);
    }
    const double cpu_ms = 1000.0 * (CpuSeconds() - cpu0) / opt.runs;
    std::vector<double> sorted = wall;
    std::sort(sorted.begin(), sorted.end());
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("session: %s (%zu poses%s x %zu frames, %d threads)\n", opt.session.c_str(),
                session->poses.size(), opt.repeat_to > 0 ? " repeated" : "", frames, opt.threads);
    std::printf("result: %s, %d poses used\n", status.c_str(), poses_used);
    std::printf("start-up (boxd --help, median of 5): %.1f ms\n", startup_ms);
    std::printf("load (PNG decode): %.1f ms\n", load_ms);
    std::printf("processing over %d runs: median %.1f ms, min %.1f ms, max %.1f ms\n", opt.runs,
                sorted[sorted.size() / 2], sorted.front(), sorted.back());
    std::printf("CPU time per run (all threads): %.1f ms\n", cpu_ms);
    std::printf("stage medians:");
    for (const auto& [name, ms] : stages) {
        if (name != "capture" && name != "processing")
            std::printf(" %s %.1f ms", name.c_str(), Median(ms));
    }
    std::printf("\n");
    std::printf("peak RSS: %.1f MB\n", static_cast<double>(usage.ru_maxrss) / 1024.0);
    return kExitOk;
}

}  // namespace

void AddBenchMeasure(CLI::App& app, Runner& run) {
    auto opt = std::make_shared<BenchOptions>();
    CLI::App* sub =
        app.add_subcommand("bench-measure", "Time the measurement pipeline on a session");
    sub->add_option("--session", opt->session, "session folder (boxd.session/1)")->required();
    sub->add_option("--runs", opt->runs, "number of timed runs")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    sub->add_option("--threads", opt->threads, "worker threads")
        ->check(CLI::Range(1, 64))
        ->capture_default_str();
    sub->add_option("--repeat-to", opt->repeat_to,
                    "measure a disagreeing session of this many poses: the session's poses "
                    "repeated in turn under evenly spaced angles")
        ->check(CLI::Range(1, 360));
    sub->callback([&run, opt] { run = [opt] { return RunBench(*opt); }; });
}

}  // namespace boxd::cli
