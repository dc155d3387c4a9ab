// The `scale:` section: defaults, every key read, and a wrong one named.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "drivers/scale.h"
#include "drivers/station_config.h"

namespace boxd {
namespace {

TEST(ScaleConfig, AbsentMeansNoScale) {
    auto none = ParseScaleConfig(YAML::Node());
    ASSERT_TRUE(none.ok());
    EXPECT_FALSE(none->enabled());
    auto station = ParseStationConfig(YAML::Load("camera: {driver: simulated}"));
    ASSERT_TRUE(station.ok()) << station.error().message;
    EXPECT_FALSE(station->scale.enabled());
}

TEST(ScaleConfig, ReadsEveryKey) {
    auto c = ParseScaleConfig(YAML::Load(R"(
driver: modbus-rtu
device: /dev/ttyS3
baud: 19200
parity: E
slave_id: 4
unit: lb
count: 0.01
division: 0.02
min_weight: 0.4
capacity: 150
read: net
stable_time_ms: 800
stable_band_divisions: 2
use_stable_flag: false
poll_interval_ms: 40
timeout_ms: 6000
registers: {weight_register: 100, net_register: 102, word_order: low_first, status_register: 104,
            stable_bit: 3, overload_bit: 4, underload_bit: 5, command_register: 110,
            command_zero: 7, command_tare: 8}
)"));
    ASSERT_TRUE(c.ok()) << c.error().message;
    EXPECT_EQ(c->driver, "modbus-rtu");
    EXPECT_EQ(c->parity, "E");
    EXPECT_EQ(c->unit, "lb");
    EXPECT_DOUBLE_EQ(c->division, 0.02);
    EXPECT_EQ(c->read, "net");
    EXPECT_FALSE(c->use_stable_flag);
    EXPECT_EQ(c->registers.word_order, WordOrder::kLowFirst);
    EXPECT_EQ(c->registers.net_register, 102);
    EXPECT_EQ(c->registers.command_tare, 8);
}

TEST(ScaleConfig, AWrongKeyOrValueIsNamed) {
    const struct {
        const char* yaml;
        const char* says;
    } cases[] = {
        {"driver: usb", "scale.driver: must be none, modbus-tcp"},
        {"driver: modbus-tcp\nport: 0", "scale.port"},
        {"unit: g", "scale.unit: must be kg or lb"},
        {"divison: 0.005", "scale.divison: unknown key"},
        {"count: 0.01\ndivision: 0.005", "scale.division: must not be finer"},
        {"min_weight: 80", "scale.min_weight"},
        {"stable_time_ms: 5000\ntimeout_ms: 1000", "scale.timeout_ms"},
        {"read: tare", "scale.read"},
        {"registers: {stable_bit: 16}", "scale.registers.stable_bit"},
        {"registers: {word_order: middle}", "scale.registers.word_order"},
        {"driver: simulated\nsimulated: {fault: fire}", "scale.simulated.fault"},
        {"driver: simulated\nsimulated: {load: -1}", "scale.simulated.load"},
        {"division: heavy", "scale.division: cannot read"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.yaml);
        auto parsed = ParseScaleConfig(YAML::Load(c.yaml));
        ASSERT_FALSE(parsed.ok());
        EXPECT_EQ(parsed.error().code, ErrorCode::kInvalidInput);
        EXPECT_NE(parsed.error().message.find(c.says), std::string::npos) << parsed.error().message;
    }
}

}  // namespace
}  // namespace boxd
