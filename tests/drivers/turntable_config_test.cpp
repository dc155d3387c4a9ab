// TurntableConfig / TurntableProfile: YAML parsing, validation naming the field, word order.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "drivers/turntable.h"

namespace boxd {
namespace {

TEST(TurntableConfig, DefaultsAreValidAndFollowTheSpecProfile) {
    TurntableConfig c;
    EXPECT_TRUE(c.Validate().ok());
    EXPECT_EQ(c.profile.command_register, 0);
    EXPECT_EQ(c.profile.target_register, 1);
    EXPECT_EQ(c.profile.speed_register, 3);
    EXPECT_EQ(c.profile.status_register, 10);
    EXPECT_EQ(c.profile.angle_register, 11);
    EXPECT_EQ(c.profile.fault_code_register, 13);
    EXPECT_EQ(c.profile.word_order, WordOrder::kHighFirst);
    EXPECT_DOUBLE_EQ(c.profile.angle_units_per_deg, 100.0);
}

TEST(TurntableConfig, ParsesFieldsAndProfileOverrides) {
    const YAML::Node node = YAML::Load(R"(
driver: modbus-rtu
device: /dev/ttyS3
baud: 38400
parity: E
slave_id: 7
response_timeout_ms: 150
retries: 4
move_timeout_ms: 9000
angle_tolerance_deg: 0.2
speed_dps: 45
profile:
  status_register: 20
  angle_register: 30
  word_order: low_first
  angle_units_per_deg: -1000
  fault_code_register: -1
  fault_names: {5: encoder lost}
)");
    auto c = ParseTurntableConfig(node);
    ASSERT_TRUE(c.ok()) << c.error().message;
    EXPECT_EQ(c->driver, "modbus-rtu");
    EXPECT_EQ(c->device, "/dev/ttyS3");
    EXPECT_EQ(c->baud, 38400);
    EXPECT_EQ(c->parity, "E");
    EXPECT_EQ(c->slave_id, 7);
    EXPECT_EQ(c->response_timeout_ms, 150);
    EXPECT_EQ(c->retries, 4);
    EXPECT_EQ(c->move_timeout_ms, 9000);
    EXPECT_DOUBLE_EQ(c->angle_tolerance_deg, 0.2);
    EXPECT_DOUBLE_EQ(c->speed_dps, 45.0);
    EXPECT_EQ(c->profile.status_register, 20);
    EXPECT_EQ(c->profile.angle_register, 30);
    EXPECT_EQ(c->profile.word_order, WordOrder::kLowFirst);
    EXPECT_DOUBLE_EQ(c->profile.angle_units_per_deg, -1000.0);
    EXPECT_EQ(c->profile.fault_code_register, -1);
    EXPECT_EQ(DescribeFaultCode(c->profile, 5), "encoder lost (code 5)");
    EXPECT_EQ(DescribeFaultCode(c->profile, 1), "code 1");
    EXPECT_EQ(c->profile.command_register, 0) << "unset profile fields keep their defaults";
}

TEST(TurntableConfig, EmptySectionGivesDefaults) {
    auto c = ParseTurntableConfig(YAML::Node());
    ASSERT_TRUE(c.ok());
    EXPECT_EQ(c->driver, "modbus-tcp");
    EXPECT_EQ(c->port, 5020);
}

struct BadConfigCase {
    const char* yaml;
    const char* field;
};

// Names the case by its field in test listings.
void PrintTo(const BadConfigCase& c, std::ostream* os) { *os << c.field; }

class TurntableConfigErrors : public ::testing::TestWithParam<BadConfigCase> {};

TEST_P(TurntableConfigErrors, NameTheField) {
    auto c = ParseTurntableConfig(YAML::Load(GetParam().yaml));
    ASSERT_FALSE(c.ok()) << GetParam().yaml;
    EXPECT_EQ(c.error().code, ErrorCode::kInvalidInput);
    EXPECT_NE(c.error().message.find(GetParam().field), std::string::npos) << c.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TurntableConfigErrors,
    ::testing::Values(
        BadConfigCase{"driver: canbus", "turntable.driver"},
        BadConfigCase{"port: 70000", "turntable.port"},
        BadConfigCase{"port: http", "turntable.port"},
        BadConfigCase{"slave_id: 0", "turntable.slave_id"},
        BadConfigCase{"parity: X", "turntable.parity"},
        BadConfigCase{"response_timeout_ms: 0", "turntable.response_timeout_ms"},
        BadConfigCase{"retries: -1", "turntable.retries"},
        BadConfigCase{"angle_tolerance_deg: 0", "turntable.angle_tolerance_deg"},
        BadConfigCase{"speed_dps: 7000", "turntable.speed_dps"},
        BadConfigCase{"direction: up", "turntable.direction"},
        BadConfigCase{"spead_dps: 10", "turntable.spead_dps"},
        BadConfigCase{"profile: {homed_bit: 16}", "turntable.profile.homed_bit"},
        BadConfigCase{"profile: {moving_bit: 0}", "turntable.profile.moving_bit"},
        BadConfigCase{"profile: {word_order: middle}", "turntable.profile.word_order"},
        BadConfigCase{"profile: {angle_units_per_deg: 0}", "turntable.profile.angle_units_per_deg"},
        BadConfigCase{"profile: {target_register: 65535}", "turntable.profile.target_register"},
        BadConfigCase{"profile: {command_stop: 1}", "turntable.profile.command_stop"},
        BadConfigCase{"profile: {colour: red}", "turntable.profile.colour"}));

TEST(TurntableProfile, Int32WordOrderRoundTrips) {
    uint16_t words[2];
    SplitInt32(-2000, WordOrder::kHighFirst, words);
    EXPECT_EQ(words[0], 0xFFFF);
    EXPECT_EQ(words[1], 0xF830);
    EXPECT_EQ(JoinInt32(words, WordOrder::kHighFirst), -2000);
    SplitInt32(0x12345678, WordOrder::kLowFirst, words);
    EXPECT_EQ(words[0], 0x5678);
    EXPECT_EQ(words[1], 0x1234);
    EXPECT_EQ(JoinInt32(words, WordOrder::kLowFirst), 0x12345678);
    EXPECT_NE(JoinInt32(words, WordOrder::kHighFirst), 0x12345678);
}

}  // namespace
}  // namespace boxd
