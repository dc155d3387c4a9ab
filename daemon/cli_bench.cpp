// boxd bench-measure: times the measurement pipeline on one session (the figures behind the
// speed target): load time, then median/min/max processing wall time over N runs, and peak RSS.
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "daemon/cli.h"
#include "pipeline/measure_pipeline.h"
#include "pipeline/session_io.h"

namespace boxd::cli {

namespace {

struct BenchOptions {
    std::string session;
    int runs = 5;
    int threads = 2;
};

int RunBench(const BenchOptions& opt) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    auto session = LoadSession(opt.session);
    if (!session) return FailBadInput(session.error().message);
    const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    MeasureConfig config;
    config.threads = opt.threads;
    config.registration.threads = opt.threads;
    std::vector<double> wall;
    std::string status;
    for (int i = 0; i < opt.runs; ++i) {
        const auto a = Clock::now();
        auto out = MeasureSession(*session, config, BoxMethod::kFootprint);
        wall.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
        if (!out) {
            std::fprintf(stderr, "boxd: bench-measure: %s\n", out.error().message.c_str());
            return kExitInternal;
        }
        status = StatusName(out->result.status);
    }
    std::vector<double> sorted = wall;
    std::sort(sorted.begin(), sorted.end());
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("session: %s (%zu poses, status %s, %d threads)\n", opt.session.c_str(),
                session->poses.size(), status.c_str(), opt.threads);
    std::printf("load (PNG decode): %.1f ms\n", load_ms);
    std::printf("processing over %d runs: median %.1f ms, min %.1f ms, max %.1f ms\n", opt.runs,
                sorted[sorted.size() / 2], sorted.front(), sorted.back());
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
