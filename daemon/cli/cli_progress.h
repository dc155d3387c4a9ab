#pragma once
// Progress of a long command (calibrate, record, measure) on stderr, where the logs go too: on a
// terminal one line redrawn in place, a bar with the step and its count; otherwise (a log file,
// CI, a pipe) a plain line per step, nothing redrawn. What is often quick shows it only once it
// runs long: nothing is written in its first `quiet` (a 0.3 s measurement prints no progress).

#include <chrono>
#include <string>

namespace boxd::cli {

class Progress {
public:
    // `task` names the command in every line ("calibrate").
    explicit Progress(std::string task,
                      std::chrono::milliseconds quiet = std::chrono::milliseconds(1000));
    // Ends a bar left open.
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    // Reports `done` of `total` of the step `step` ("pose", "refining"): the bar is redrawn, or
    // one line "boxd: calibrate: refining 2 of 4" is written.
    void Step(const std::string& step, int done, int total);
    // Ends the bar's line (a terminal), so that what follows starts on a line of its own.
    void Finish();

private:
    std::string task_;
    std::chrono::steady_clock::time_point show_from_;
    bool terminal_;
    bool open_ = false;  // a bar is drawn and its line not ended
};

}  // namespace boxd::cli
