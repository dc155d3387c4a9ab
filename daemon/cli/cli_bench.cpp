// boxd bench-measure: times the measurement pipeline on one session (the figures behind the
// speed target): load time, then median/min/max processing wall time over N runs, and peak RSS.
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "daemon/cli/cli.h"
#include "pipeline/measure_pipeline.h"
#include "pipeline/session_io.h"

namespace boxd::cli {

namespace {

struct BenchOptions {
    std::string session;
    int runs = 5;
    int threads = 2;
};

double CpuSeconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double Median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

int RunBench(const BenchOptions& opt) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    auto session = LoadSession(opt.session);
    if (!session) return Fail(session.error());
    const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    MeasureConfig config;
    config.threads = opt.threads;
    config.registration.threads = opt.threads;
    std::vector<double> wall;
    std::map<std::string, std::vector<double>> stages;
    std::string status;
    const double cpu0 = CpuSeconds();
    for (int i = 0; i < opt.runs; ++i) {
        const auto a = Clock::now();
        auto out = MeasureSession(*session, config, BoxMethod::kFootprint, SteadyClockMs());
        wall.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
        if (!out) return Fail(out.error());
        status = StatusName(out->result.status);
        for (const auto& [name, ms] : out->result.timing_ms) stages[name].push_back(ms);
    }
    const double cpu_ms = 1000.0 * (CpuSeconds() - cpu0) / opt.runs;
    std::vector<double> sorted = wall;
    std::sort(sorted.begin(), sorted.end());
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("session: %s (%zu poses, status %s, %d threads)\n", opt.session.c_str(),
                session->poses.size(), status.c_str(), opt.threads);
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
    sub->callback([&run, opt] { run = [opt] { return RunBench(*opt); }; });
}

}  // namespace boxd::cli
