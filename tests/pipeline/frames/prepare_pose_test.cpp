#include "pipeline/frames/prepare_pose.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/refusal.h"
#include "tests/support/expect_error.h"

namespace boxd {
namespace {

constexpr int kW = 16;
constexpr int kH = 12;

// A gently sloping surface: raw value base + x + y. Neighbours differ by at most 2 units
// (2 mm at 1 mm units), far below the flying-pixel jump of 12 mm + 1.2% of z, so the filter
// leaves every pixel alone.
DepthImage Ramp(std::uint16_t base) {
    DepthImage img(kW, kH);
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) img.at(x, y) = static_cast<std::uint16_t>(base + x + y);
    }
    return img;
}

// Expects `depth` to be Ramp(base) in metres at `unit_m` per raw unit.
void ExpectRampInMetres(const DepthMap& depth, std::uint16_t base, double unit_m) {
    ASSERT_EQ(depth.width, kW);
    ASSERT_EQ(depth.height, kH);
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            // The average of equal readings is the reading: float rounding only (< 1e-6 m).
            EXPECT_NEAR(depth.at(x, y), (base + x + y) * unit_m, 1e-6) << x << "," << y;
        }
    }
}

// A depth map of kW x kH with `valid` readings of 1 m (the first pixels in row-major order).
DepthMap WithValidPixels(int valid) {
    DepthMap d(kW, kH);
    for (int i = 0; i < valid; ++i) d.z_m[static_cast<std::size_t>(i)] = 1.0f;
    return d;
}

PreparedPose Prepared(DepthMap depth) { return PreparedPose{std::move(depth), ""}; }

TEST(PreparePose, IdenticalFramesGiveTheirDepthInMetres) {
    const std::vector<DepthImage> frames(5, Ramp(900));
    const PreparedPose p = PreparePose(frames, 0.001, FrameConfig{});
    EXPECT_TRUE(p.error.empty()) << p.error;
    ExpectRampInMetres(p.depth, 900, 0.001);
}

TEST(PreparePose, UsesTheCameraDepthUnit) {
    // The same raw values at 0.5 mm per unit read half as deep.
    const std::vector<DepthImage> frames(3, Ramp(1800));
    const PreparedPose p = PreparePose(frames, 0.0005, FrameConfig{});
    EXPECT_TRUE(p.error.empty()) << p.error;
    ExpectRampInMetres(p.depth, 1800, 0.0005);
}

TEST(PreparePose, RemovesFlyingPixelsAsConfigured) {
    // One pixel 10 cm in front of its neighbours is a flying pixel: removed with the default
    // filter (a jump above 12 mm + 1.2% of z), kept with passes = 0.
    DepthImage img = Ramp(900);
    img.at(7, 5) = 800;
    const std::vector<DepthImage> frames(3, img);
    FrameConfig config;
    const PreparedPose filtered = PreparePose(frames, 0.001, config);
    ASSERT_TRUE(filtered.error.empty()) << filtered.error;
    EXPECT_EQ(filtered.depth.at(7, 5), 0.0f);
    EXPECT_NEAR(filtered.depth.at(0, 0), 0.9, 1e-6);
    config.flying_pixels.passes = 0;
    const PreparedPose kept = PreparePose(frames, 0.001, config);
    EXPECT_NEAR(kept.depth.at(7, 5), 0.8, 1e-6);
}

TEST(PreparePose, FramesThatCannotBeAveragedGiveAnError) {
    const PreparedPose none = PreparePose({}, 0.001, FrameConfig{});
    EXPECT_FALSE(none.error.empty());
    EXPECT_TRUE(none.depth.z_m.empty());
    const PreparedPose mixed =
        PreparePose({Ramp(900), DepthImage(kW + 1, kH)}, 0.001, FrameConfig{});
    EXPECT_FALSE(mixed.error.empty());
    EXPECT_TRUE(mixed.depth.z_m.empty());
}

// Four poses with distinct depths (pose k at 800 + 50 k mm) and a fifth whose frames differ in
// size, at 1 mm per unit.
Session FivePoses() {
    Session s;
    s.camera.depth_unit_m = 0.001;
    for (int k = 0; k < 4; ++k) {
        SessionPose pose;
        pose.angle_deg = 90.0 * k;
        pose.frames.assign(3, Ramp(static_cast<std::uint16_t>(800 + 50 * k)));
        s.poses.push_back(pose);
    }
    SessionPose bad;
    bad.frames = {Ramp(900), DepthImage(kW, kH + 1)};
    s.poses.push_back(bad);
    return s;
}

TEST(PrepareSession, PreparesEveryPoseInOrderOnOneAndTwoThreads) {
    const Session session = FivePoses();
    FrameConfig config;
    config.threads = 1;
    const std::vector<PreparedPose> one = PrepareSession(session, config);
    config.threads = 2;
    const std::vector<PreparedPose> two = PrepareSession(session, config);
    ASSERT_EQ(one.size(), 5u);
    ASSERT_EQ(two.size(), 5u);
    for (int k = 0; k < 4; ++k) {
        SCOPED_TRACE(k);
        const auto i = static_cast<std::size_t>(k);
        EXPECT_TRUE(one[i].error.empty()) << one[i].error;
        ExpectRampInMetres(one[i].depth, static_cast<std::uint16_t>(800 + 50 * k), 0.001);
        EXPECT_EQ(one[i].depth.z_m, two[i].depth.z_m);  // bit for bit
        EXPECT_EQ(two[i].error, one[i].error);
    }
    EXPECT_FALSE(one[4].error.empty());
    EXPECT_EQ(two[4].error, one[4].error);
}

TEST(UsableDepths, NoPosesIsInsufficientData) {
    test::ExpectError(UsableDepths({}, RefusalConfig{}), ErrorCode::kInsufficientData);
}

TEST(UsableDepths, PoseWithAnErrorIsInsufficientDataNamingIt) {
    std::vector<PreparedPose> poses = {Prepared(WithValidPixels(kW * kH)),
                                       Prepared(WithValidPixels(kW * kH)),
                                       PreparedPose{DepthMap{}, "frames of one pose differ"}};
    const auto r = UsableDepths(std::move(poses), RefusalConfig{});
    test::ExpectError(r, ErrorCode::kInsufficientData);
    if (r.ok()) return;
    EXPECT_NE(r.error().message.find("pose 2"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("frames of one pose differ"), std::string::npos)
        << r.error().message;
}

TEST(UsableDepths, PoseWithTooFewValidPixelsIsInsufficientDataNamingIt) {
    // 192 pixels at the default 5% need 9.6 readings: 9 are too few, 10 enough.
    const RefusalConfig refuse;
    ASSERT_EQ(refuse.min_pose_valid_fraction, 0.05);
    std::vector<PreparedPose> poses = {Prepared(WithValidPixels(10)), Prepared(WithValidPixels(9))};
    const auto r = UsableDepths(poses, refuse);
    test::ExpectError(r, ErrorCode::kInsufficientData);
    if (!r.ok()) {
        EXPECT_NE(r.error().message.find("pose 1"), std::string::npos) << r.error().message;
    }
    poses[1] = Prepared(WithValidPixels(10));
    EXPECT_TRUE(UsableDepths(poses, refuse).ok());
}

TEST(UsableDepths, ValidPosesComeBackInOrder) {
    std::vector<PreparedPose> poses;
    for (int k = 0; k < 3; ++k) {
        DepthMap d = WithValidPixels(kW * kH);
        for (float& z : d.z_m) z = 0.5f + 0.25f * static_cast<float>(k);
        poses.push_back(Prepared(d));
    }
    const auto r = UsableDepths(poses, RefusalConfig{});
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ((*r)[k].z_m, poses[k].depth.z_m) << k;
}

}  // namespace
}  // namespace boxd
