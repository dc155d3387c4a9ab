// The systemd notifier against a real AF_UNIX datagram socket standing in for systemd's
// NOTIFY_SOCKET.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <optional>
#include <string>

#include "daemon/service/systemd_notifier.h"
#include "tests/support/serve_daemon.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using test::NotifySocket;

class SystemdNotifierTest : public ::testing::Test {
protected:
    void TearDown() override {
        unsetenv("NOTIFY_SOCKET");
        unsetenv("WATCHDOG_USEC");
        unsetenv("WATCHDOG_PID");
    }
    test::TempDir dir_;
};

TEST_F(SystemdNotifierTest, SendsReadyWatchdogStatusAndStopping) {
    NotifySocket sock(dir_ / "notify");
    ASSERT_TRUE(sock.bound());
    setenv("NOTIFY_SOCKET", (dir_ / "notify").c_str(), 1);
    setenv("WATCHDOG_USEC", "3000000", 1);
    setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);
    SystemdNotifier notifier;
    ASSERT_TRUE(notifier.enabled());
    EXPECT_EQ(notifier.watchdog_interval().count(), 1500);  // half of WatchdogSec

    notifier.Ready("idle");
    auto ready = sock.Receive();
    ASSERT_TRUE(ready);
    EXPECT_NE(ready->find("READY=1"), std::string::npos);
    EXPECT_NE(ready->find("STATUS=idle"), std::string::npos);

    notifier.Watchdog();
    EXPECT_EQ(sock.Receive(), "WATCHDOG=1");

    notifier.Status("measuring m-000001:\ncapture pose 3/18");
    EXPECT_EQ(sock.Receive(), "STATUS=measuring m-000001: capture pose 3/18");  // one line

    notifier.Stopping("stopping");
    auto stopping = sock.Receive();
    ASSERT_TRUE(stopping);
    EXPECT_NE(stopping->find("STOPPING=1"), std::string::npos);
}

TEST_F(SystemdNotifierTest, WatchdogMeantForAnotherProcessIsIgnored) {
    setenv("NOTIFY_SOCKET", (dir_ / "notify").c_str(), 1);
    setenv("WATCHDOG_USEC", "3000000", 1);
    setenv("WATCHDOG_PID", std::to_string(getpid() + 1).c_str(), 1);
    SystemdNotifier notifier;
    EXPECT_EQ(notifier.watchdog_interval().count(), 0);
}

TEST_F(SystemdNotifierTest, IsANoOpWithoutNotifySocket) {
    unsetenv("NOTIFY_SOCKET");
    NotifySocket sock(dir_ / "notify");
    ASSERT_TRUE(sock.bound());
    SystemdNotifier notifier;
    EXPECT_FALSE(notifier.enabled());
    EXPECT_EQ(notifier.watchdog_interval().count(), 0);
    notifier.Ready("idle");  // must neither fail nor send anything anywhere
    notifier.Watchdog();
    notifier.Stopping("stopping");
    EXPECT_FALSE(sock.Receive().has_value());
}

}  // namespace
}  // namespace boxd
