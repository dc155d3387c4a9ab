// The metrological event counter (daemon/service/audit_trail.h) on a real data folder: the first
// value of a setting is no event, each change is one with what, from, to and via, the counter
// survives a reopen and never falls.
#include "daemon/service/audit_trail.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

TEST(AuditTrail, TheFirstValueIsNoEventAndEachChangeIsOne) {
    test::TempDir dir;
    auto trail = AuditTrail::Open(dir.path());
    ASSERT_TRUE(trail) << trail.error().message;
    auto first = (*trail)->Observe("billing", "{\"division_m\":\"0.005\"}", "config at start");
    ASSERT_TRUE(first);
    EXPECT_FALSE(*first);
    EXPECT_EQ((*trail)->Counter(), 0);
    EXPECT_FALSE(*(*trail)->Observe("billing", "{\"division_m\":\"0.005\"}", "config at start"));
    EXPECT_TRUE(*(*trail)->Observe("billing", "{\"division_m\":\"0.01\"}", "SIGHUP reload"));
    EXPECT_EQ((*trail)->Counter(), 1);
    auto events = (*trail)->Events(10);
    ASSERT_TRUE(events);
    ASSERT_EQ(events->size(), 1u);
    const AuditEvent& e = events->front();
    EXPECT_EQ(e.counter, 1);
    EXPECT_EQ(e.what, "billing");
    EXPECT_EQ(e.from, "{\"division_m\":\"0.005\"}");
    EXPECT_EQ(e.to, "{\"division_m\":\"0.01\"}");
    EXPECT_EQ(e.via, "SIGHUP reload");
    EXPECT_EQ(e.at.size(), 24u);  // 2026-12-05T10:00:00.000Z
}

TEST(AuditTrail, TheCounterSurvivesAReopenAndNeverFalls) {
    test::TempDir dir;
    {
        auto trail = AuditTrail::Open(dir.path());
        ASSERT_TRUE(trail);
        ASSERT_TRUE((*trail)->Observe("calibration", "A", "config at start"));
        ASSERT_TRUE((*trail)->Observe("calibration", "B", "POST /v1/calibrate"));
        ASSERT_TRUE((*trail)->Observe("software", "v1", "start"));
        ASSERT_TRUE((*trail)->Observe("software", "v2", "start"));
        EXPECT_EQ((*trail)->Counter(), 2);
    }
    auto trail = AuditTrail::Open(dir.path());
    ASSERT_TRUE(trail);
    EXPECT_EQ((*trail)->Counter(), 2);
    // Back to an earlier value is a change too: the counter goes on rising.
    EXPECT_TRUE(*(*trail)->Observe("calibration", "A", "SIGHUP reload"));
    EXPECT_EQ((*trail)->Counter(), 3);
    auto events = (*trail)->Events(2);
    ASSERT_TRUE(events);
    ASSERT_EQ(events->size(), 2u);
    EXPECT_EQ((*events)[0].counter, 3);  // newest first
    EXPECT_EQ((*events)[0].from, "B");
    EXPECT_EQ((*events)[1].what, "software");
}

TEST(AuditTrail, ASectionsTextDoesNotDependOnTheOrderOfItsKeys) {
    EXPECT_EQ(SectionText(YAML::Load("{b: 1, a: [2, 3]}")),
              SectionText(YAML::Load("{a: [2, 3], b: 1}")));
    EXPECT_NE(SectionText(YAML::Load("{a: 1}")), SectionText(YAML::Load("{a: 2}")));
    EXPECT_EQ(SectionText(YAML::Node()), "none");
}

}  // namespace
}  // namespace boxd
