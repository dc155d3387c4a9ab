#include "pipeline/measure_config.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/support/expect_error.h"

namespace boxd {
namespace {

// Expects `s` to fail with INVALID_CONFIG and a message naming `field`.
void ExpectInvalidNaming(const Status& s, const std::string& field) {
    test::ExpectError(s, ErrorCode::kInvalidConfig);
    if (s.ok()) return;
    EXPECT_NE(s.error().message.find(field), std::string::npos) << s.error().message;
}

TEST(MeasureConfig, DefaultsValidate) {
    const Status s = MeasureConfig{}.Validate();
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    EXPECT_TRUE(ConfidenceConfig{}.Validate().ok());
}

TEST(MeasureConfig, BadRefusalValueNamesTheField) {
    MeasureConfig c;
    c.refusal.min_pose_valid_fraction = 1.0;  // [0, 1): every pose would be refused
    ExpectInvalidNaming(c.Validate(), "refusal.min_pose_valid_fraction");
    c = MeasureConfig{};
    c.refusal.min_object_points = 5;
    ExpectInvalidNaming(c.Validate(), "refusal.min_object_points");
}

TEST(MeasureConfig, BadEnvelopeValueNamesTheField) {
    MeasureConfig c;
    c.envelope.min_fill = 0.0;
    ExpectInvalidNaming(c.Validate(), "envelope.min_fill");
    c = MeasureConfig{};
    c.envelope.false_alarm = 0.5;
    ExpectInvalidNaming(c.Validate(), "envelope.false_alarm");
}

TEST(MeasureConfig, BadConfidenceValueNamesTheField) {
    MeasureConfig c;
    c.confidence.rmse_scale_m = 0.0;
    ExpectInvalidNaming(c.Validate(), "confidence.rmse_scale_m");
    c = MeasureConfig{};
    c.confidence.face_sigma_scale_m = -0.01;
    ExpectInvalidNaming(c.Validate(), "confidence.face_sigma_scale_m");
    c = MeasureConfig{};
    c.confidence.full_points = 0;
    ExpectInvalidNaming(c.Validate(), "confidence.full_points");
    c = MeasureConfig{};
    c.confidence.single_view_share = 1.5;
    ExpectInvalidNaming(c.Validate(), "confidence.single_view_share");
    c.confidence.single_view_share = 1.0;  // the closed end of (0, 1]
    EXPECT_TRUE(c.Validate().ok());
}

TEST(MeasureConfig, ThreadsOutsideOneToSixtyFourNamesTheField) {
    MeasureConfig c;
    for (int threads : {0, -1, 65}) {
        c.threads = threads;
        ExpectInvalidNaming(c.Validate(), "threads");
    }
    for (int threads : {1, 64}) {
        c.threads = threads;
        EXPECT_TRUE(c.Validate().ok()) << threads;
    }
}

TEST(MeasureConfig, NaNIsRejected) {
    // Comparisons with NaN are false: a check written as `x <= 0` would let NaN through.
    MeasureConfig c;
    c.confidence.rmse_scale_m = std::nan("");
    ExpectInvalidNaming(c.Validate(), "confidence.rmse_scale_m");
    c = MeasureConfig{};
    c.refusal.min_dimension_m = std::nan("");
    ExpectInvalidNaming(c.Validate(), "refusal.min_dimension_m");
}

TEST(MeasureConfig, NamesTheFirstBadSectionInRecipeOrder) {
    // Averaging comes first in the recipe, confidence last: the error names averaging.
    MeasureConfig c;
    c.averaging.min_valid_fraction = 0.0;
    c.confidence.full_points = 0;
    c.threads = 0;
    ExpectInvalidNaming(c.Validate(), "averaging.min_valid_fraction");
}

TEST(BoxMethodName, NamesBothMethods) {
    EXPECT_STREQ(BoxMethodName(BoxMethod::kFootprint), "footprint");
    EXPECT_STREQ(BoxMethodName(BoxMethod::kPca), "pca");
}

}  // namespace
}  // namespace boxd
