// The motion criterion of drivers/weighing.h on scripted indicators and a scripted clock: a
// weight is taken once the readings of the stable time agree within the band (and the
// indicator says stable), to the division; overload, underload, motion and drift end in a
// SCALE_ERROR that says which; a load below Min is weighed but not stated.
#include "drivers/weighing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "tests/support/expect_error.h"

namespace boxd {
namespace {

// An indicator whose reading is a function of the scripted time.
class ScriptedScale : public Scale {
public:
    ScriptedScale(const double* now_ms, std::function<ScaleReading(double)> at)
        : now_ms_(now_ms), at_(std::move(at)) {}
    Result<ScaleReading> Read() override {
        ++reads;
        if (fail_after >= 0 && reads > fail_after) {
            return Error{ErrorCode::kScaleError, "scripted: no reply within 300 ms"};
        }
        return at_(*now_ms_);
    }
    Status Zero() override { return OkStatus(); }
    Status Tare() override { return OkStatus(); }
    std::string Describe() const override { return "scripted"; }

    int reads = 0;
    int fail_after = -1;

private:
    const double* now_ms_;
    std::function<ScaleReading(double)> at_;
};

ScaleConfig Criterion() {
    ScaleConfig c;
    c.division = 0.005;
    c.min_weight = 0.1;
    c.capacity = 60.0;
    c.stable_time_ms = 500;
    c.stable_band_divisions = 1.0;
    c.poll_interval_ms = 50;
    c.timeout_ms = 3000;
    return c;
}

struct Scripted {
    double now = 0.0;
    WeighingClock clock{[this] { return now; }, [this](int ms) { now += ms; }};
};

// The reading an indicator shows: `w` in whole divisions of 5 g.
double Shown(double w) { return std::round(w / 0.005) * 0.005; }

TEST(Weighing, TakesTheMeanOfAStableWindowToTheDivision) {
    Scripted t;
    // A 3.2 kg parcel ringing down over ~0.6 s; the indicator flags stable from 0.7 s.
    ScriptedScale scale(&t.now, [](double ms) {
        const double w = 3.2 * (1.0 - std::exp(-ms / 80.0) * std::cos(ms / 40.0));
        return ScaleReading{Shown(w), ms > 700.0, false, false};
    });
    Result<Weighing> w = WeighStable(scale, Criterion(), nullptr, t.clock);
    ASSERT_TRUE(w.ok()) << w.error().message;
    ASSERT_TRUE(w->value.has_value());
    EXPECT_NEAR(*w->value, 3.2, 1e-9);
    EXPECT_EQ(w->unit, "kg");
    EXPECT_DOUBLE_EQ(w->division, 0.005);
    // Not before the flag plus one stable time, and not long after.
    EXPECT_GE(w->settled_ms, 700.0 + 500.0);
    EXPECT_LE(w->settled_ms, 700.0 + 500.0 + 100.0);
    EXPECT_EQ(w->readings, scale.reads);
}

TEST(Weighing, ReadingsWithinTheBandAreAveragedThenRounded) {
    Scripted t;
    // Alternating 1.000 and 1.005 kg: within one division, mean 1.0025 rounds to 1.005 or
    // 1.000 by the count of each; with an odd count starting at 1.005 the mean leans up.
    ScriptedScale scale(&t.now, [](double ms) {
        const bool odd = static_cast<long>(ms / 50.0) % 2 == 0;
        return ScaleReading{odd ? 1.005 : 1.000, true, false, false};
    });
    Result<Weighing> w = WeighStable(scale, Criterion(), nullptr, t.clock);
    ASSERT_TRUE(w.ok()) << w.error().message;
    ASSERT_TRUE(w->value.has_value());
    // 11 readings over 500 ms: six of 1.005, five of 1.000 → 1.00273 → 1.005.
    EXPECT_NEAR(*w->value, 1.005, 1e-9);
}

TEST(Weighing, ASwingLargerThanTheBandIsNeverStable) {
    Scripted t;
    ScriptedScale scale(&t.now, [](double ms) {
        return ScaleReading{Shown(5.0 + 0.02 * std::sin(ms / 80.0)), false, false, false};
    });
    Result<Weighing> w = WeighStable(scale, Criterion(), nullptr, t.clock);
    test::ExpectError(w, ErrorCode::kScaleError);
    EXPECT_NE(w.error().message.find("never settled"), std::string::npos) << w.error().message;
    EXPECT_NE(w.error().message.find("within 3000 ms"), std::string::npos);
    EXPECT_GE(t.now, 3000.0);
}

TEST(Weighing, ASteadyDriftIsCalledADriftingZero) {
    Scripted t;
    ScriptedScale scale(&t.now, [](double ms) {
        return ScaleReading{Shown(2.0 + 0.03 * ms / 1000.0), true, false, false};
    });
    Result<Weighing> w = WeighStable(scale, Criterion(), nullptr, t.clock);
    test::ExpectError(w, ErrorCode::kScaleError);
    EXPECT_NE(w.error().message.find("drifting zero"), std::string::npos) << w.error().message;
}

TEST(Weighing, AnIndicatorThatNeverSaysStableIsNotOverruled) {
    Scripted t;
    ScriptedScale scale(&t.now, [](double) { return ScaleReading{4.0, false, false, false}; });
    ScaleConfig c = Criterion();
    Result<Weighing> w = WeighStable(scale, c, nullptr, t.clock);
    test::ExpectError(w, ErrorCode::kScaleError);
    EXPECT_NE(w.error().message.find("never reported a stable weight"), std::string::npos)
        << w.error().message;
    // Without the flag the readings alone decide.
    c.use_stable_flag = false;
    t.now = 0.0;
    Result<Weighing> unflagged = WeighStable(scale, c, nullptr, t.clock);
    ASSERT_TRUE(unflagged.ok()) << unflagged.error().message;
    EXPECT_NEAR(*unflagged->value, 4.0, 1e-9);
}

TEST(Weighing, AnOverloadOrUnderloadThatLastsIsTheAnswer) {
    Scripted t;
    ScriptedScale flagged(&t.now, [](double) { return ScaleReading{12.0, true, true, false}; });
    Result<Weighing> w = WeighStable(flagged, Criterion(), nullptr, t.clock);
    test::ExpectError(w, ErrorCode::kScaleError);
    EXPECT_NE(w.error().message.find("overload"), std::string::npos);
    EXPECT_NEAR(t.now, 500.0, 1e-9);  // one stable time of it, not the whole timeout
    // Above Max + 9 e without the flag is an overload all the same (OIML R76 4.2.3).
    t.now = 0.0;
    ScriptedScale heavy(&t.now, [](double) { return ScaleReading{60.05, true, false, false}; });
    test::ExpectError(WeighStable(heavy, Criterion(), nullptr, t.clock), ErrorCode::kScaleError);
    t.now = 0.0;
    ScriptedScale under(&t.now, [](double) { return ScaleReading{-1.0, true, false, true}; });
    Result<Weighing> u = WeighStable(under, Criterion(), nullptr, t.clock);
    test::ExpectError(u, ErrorCode::kScaleError);
    EXPECT_NE(u.error().message.find("underload"), std::string::npos);
}

TEST(Weighing, AMomentsOverloadAsTheParcelIsSetDownIsMotion) {
    Scripted t;
    // The first 200 ms overshoot beyond Max, then the parcel rests at 20 kg.
    ScriptedScale scale(&t.now, [](double ms) {
        return ms < 200.0 ? ScaleReading{75.0, false, true, false}
                          : ScaleReading{20.0, true, false, false};
    });
    Result<Weighing> w = WeighStable(scale, Criterion(), nullptr, t.clock);
    ASSERT_TRUE(w.ok()) << w.error().message;
    EXPECT_NEAR(*w->value, 20.0, 1e-9);
    EXPECT_GE(w->settled_ms, 200.0 + 500.0);
}

TEST(Weighing, ALoadBelowMinIsWeighedButNotStated) {
    Scripted t;
    ScriptedScale scale(&t.now, [](double) { return ScaleReading{0.06, true, false, false}; });
    Result<Weighing> w = WeighStable(scale, Criterion(), nullptr, t.clock);
    ASSERT_TRUE(w.ok()) << w.error().message;
    EXPECT_FALSE(w->value.has_value());
    EXPECT_NE(w->why_not.find("below the scale's minimum load of 0.1 kg"), std::string::npos)
        << w->why_not;
    // Exactly Min is stated.
    ScriptedScale at_min(&t.now, [](double) { return ScaleReading{0.1, true, false, false}; });
    Result<Weighing> m = WeighStable(at_min, Criterion(), nullptr, t.clock);
    ASSERT_TRUE(m.ok());
    EXPECT_TRUE(m->value.has_value());
}

TEST(Weighing, TheScalesOwnErrorAndACancelEndIt) {
    Scripted t;
    ScriptedScale scale(&t.now, [](double) { return ScaleReading{1.0, true, false, false}; });
    scale.fail_after = 3;
    Result<Weighing> w = WeighStable(scale, Criterion(), nullptr, t.clock);
    test::ExpectError(w, ErrorCode::kScaleError);
    EXPECT_NE(w.error().message.find("no reply"), std::string::npos);
    std::atomic<bool> cancel{true};
    test::ExpectError(WeighStable(scale, Criterion(), &cancel, t.clock), ErrorCode::kAborted);
}

}  // namespace
}  // namespace boxd
