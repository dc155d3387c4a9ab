#include "pipeline/core/stage_laps.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace boxd {
namespace {

// A clock that returns `times` one after the other (the constructor reads the first).
MonotonicMs FakeClock(std::vector<double> times) {
    auto next = std::make_shared<std::size_t>(0);
    return [times = std::move(times), next] { return times.at((*next)++); };
}

TEST(StageLaps, LapsAreTheDifferencesOfTheClock) {
    StageLaps laps(FakeClock({100.0, 104.5, 111.0, 111.25}));
    laps.Lap("prepare");
    laps.Lap("segmentation");
    laps.Lap("fit");
    const std::map<std::string, double> expected = {
        {"prepare", 4.5}, {"segmentation", 6.5}, {"fit", 0.25}};
    EXPECT_EQ(laps.ms(), expected);  // exact: every value is a dyadic fraction
}

TEST(StageLaps, RepeatedNameAccumulates) {
    StageLaps laps(FakeClock({0.0, 2.0, 7.0, 10.0}));
    laps.Lap("registration");
    laps.Lap("optimization");
    laps.Lap("registration");
    ASSERT_EQ(laps.ms().size(), 2u);
    EXPECT_EQ(laps.ms().at("registration"), 2.0 + 3.0);
    EXPECT_EQ(laps.ms().at("optimization"), 5.0);
}

TEST(StageLaps, NoClockGivesZeroLaps) {
    StageLaps laps;
    laps.Lap("fusion");
    laps.Lap("fit");
    ASSERT_EQ(laps.ms().size(), 2u);
    EXPECT_EQ(laps.ms().at("fusion"), 0.0);
    EXPECT_EQ(laps.ms().at("fit"), 0.0);
}

TEST(StageLaps, StartsFromTheConstructionTime) {
    // The first lap runs from construction, not from the clock's origin.
    StageLaps laps(FakeClock({5000.0, 5003.0}));
    laps.Lap("prepare");
    EXPECT_EQ(laps.ms().at("prepare"), 3.0);
}

TEST(SteadyClockMs, IsMonotonicAndInMilliseconds) {
    const MonotonicMs now = SteadyClockMs();
    double prev = now();
    for (int i = 0; i < 1000; ++i) {
        const double t = now();
        EXPECT_GE(t, prev);
        prev = t;
    }
    // sleep_for waits at least its duration: 20 ms must read as at least 20 (not 0.02 or
    // 20000 as a wrong unit would; the upper bound allows a loaded machine a full second).
    const double before = now();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const double slept = now() - before;
    EXPECT_GE(slept, 20.0);
    EXPECT_LT(slept, 1000.0);
}

TEST(SteadyClockMs, DrivesStageLaps) {
    StageLaps laps(SteadyClockMs());
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    laps.Lap("prepare");
    EXPECT_GE(laps.ms().at("prepare"), 5.0);
    EXPECT_LT(laps.ms().at("prepare"), 1000.0);
}

}  // namespace
}  // namespace boxd
