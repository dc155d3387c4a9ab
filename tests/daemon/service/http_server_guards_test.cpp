// The HTTP server's access and its defences over real TCP and Unix sockets, in-process: a bearer
// token on POSTs (and on reads where configured), the Unix socket and its mode, many byte ranges
// refused before any is built, paths that are not UTF-8, two hundred clients trickling headers
// while /v1/health answers, and the config's and the bind's errors naming their key.
#include "daemon/service/http_api.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <sys/stat.h>
#include <httplib.h>
#include <sys/socket.h>

#include <atomic>
#include <thread>

#include "daemon/service/measurement_service.h"
#include "daemon/service/measurement_store.h"
#include "tests/support/http_api_fixture.h"
#include "tests/support/scripted_station.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;
using test::HttpApiTest;

class HttpApiTokenTest : public HttpApiTest {
protected:
    // TCP on a free port and a Unix socket in the test's folder, POSTs behind a token.
    ServerConfig TokenConfig() {
        ServerConfig config;
        config.listen = "127.0.0.1:0";
        config.bearer_token = "s3cret";
        config.unix_socket = (dir_ / "boxd.sock").string();
        return config;
    }
    void SetUp() override { StartApi(TokenConfig()); }
};

TEST_F(HttpApiTokenTest, PostsNeedTheBearerTokenGetsDoNot) {
    ExpectError(client_->Post("/v1/measure", "", "application/json"), 401, "UNAUTHORIZED");
    httplib::Headers wrong = {{"Authorization", "Bearer s3cre"}};
    ExpectError(client_->Post("/v1/measure", wrong, "", "application/json"), 401, "UNAUTHORIZED");
    ExpectError(client_->Post("/v1/calibrate", wrong, "{}", "application/json"), 401,
                "UNAUTHORIZED");
    EXPECT_FALSE(service_->Busy());
    auto status = client_->Get("/v1/status");
    ASSERT_TRUE(status);
    EXPECT_EQ(status->status, 200);

    httplib::Headers right = {{"Authorization", "Bearer s3cret"}};
    auto ok = client_->Post("/v1/measure?wait=1", right, "", "application/json");
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->status, 200) << ok->body;
}

TEST_F(HttpApiTokenTest, ServesTheUnixSocketToo) {
    httplib::Client unix_client((dir_ / "boxd.sock").string(), 80);
    unix_client.set_address_family(AF_UNIX);
    auto health = unix_client.Get("/v1/health");
    ASSERT_TRUE(health) << httplib::to_string(health.error());
    EXPECT_EQ(health->status, 200);
    httplib::Headers right = {{"Authorization", "Bearer s3cret"}};
    auto ok = unix_client.Post("/v1/measure?wait=1", right, "", "application/json");
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->status, 200);
    auto last = client_->Get("/v1/measurements/last");  // and TCP sees the same store
    ASSERT_TRUE(last);
    EXPECT_EQ(Body(last)["id"], Body(ok)["id"]);
}

TEST_F(HttpApiTokenTest, TheSocketIsReadAndWrittenByOwnerAndGroupOnly) {
    struct stat st {};
    ASSERT_EQ(::stat((dir_ / "boxd.sock").c_str(), &st), 0);
    EXPECT_TRUE(S_ISSOCK(st.st_mode));
    EXPECT_EQ(st.st_mode & 0777, 0660u);
}

TEST_F(HttpApiTest, ManyByteRangesAreRefusedBeforeAnyIsBuilt) {
    // httplib would copy the body once per range into one multipart answer.
    ExpectError(client_->Get("/v1/status", {{"Range", "bytes=0-,0-,0-,0-,0-"}}), 416,
                "BAD_REQUEST");
    auto few = client_->Get("/v1/status", {{"Range", "bytes=0-9,10-19"}});
    ASSERT_TRUE(few);
    EXPECT_NE(few->status, 416);
    auto health = client_->Get("/v1/health");  // and the daemon serves on
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
}

// Opens a TCP connection to 127.0.0.1:`port`; -1 on failure.
int Connect(int port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
}

// Sends `request` (which asks for "Connection: close") on a new connection and returns the
// whole answer ("" when none came).
std::string RawExchange(int port, const std::string& request) {
    const int fd = Connect(port);
    if (fd < 0) return "";
    ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
    std::string reply;
    char buf[4096];
    for (ssize_t n; (n = ::recv(fd, buf, sizeof(buf), 0)) > 0;) reply.append(buf, n);
    ::close(fd);
    return reply;
}

TEST_F(HttpApiTest, PathsThatAreNotUtf8GetTheirErrorAndTheDaemonServesOn) {
    // Found by tests/fuzz/http_fuzz.cpp: the unknown path, echoed in the error message, is not
    // UTF-8, and writing the JSON threw out of the handler: std::terminate took the daemon down.
    for (const char* method : {"GET", "POST"}) {
        const std::string reply = RawExchange(
            api_->tcp_port(), std::string(method) + " /v1/meas\xe5ure?wait=1 HTTP/1.1\r\nHost: x\r\n"
                              "Connection: close\r\nContent-Length: 2\r\n\r\n{}");
        ASSERT_EQ(reply.rfind("HTTP/1.1 404", 0), 0u) << method << ": " << reply;
        const json body = json::parse(reply.substr(reply.find("\r\n\r\n") + 4), nullptr, false);
        ASSERT_TRUE(body.is_object()) << reply;
        EXPECT_EQ(body["error"]["code"], "NOT_FOUND");
    }
    auto health = client_->Get("/v1/health");
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
}

TEST_F(HttpApiTest, HealthAnswersWhileTwoHundredClientsTrickleHeaders) {
    // 200 connections (more than the 16 resident workers) that send a request line and then a
    // header line every 100 ms, never finishing: each holds its connection thread.
    std::vector<int> slow;
    for (int i = 0; i < 200; ++i) {
        const int fd = Connect(api_->tcp_port());
        ASSERT_GE(fd, 0);
        const std::string line = "GET /v1/status HTTP/1.1\r\nHost: x\r\n";
        ASSERT_EQ(::send(fd, line.data(), line.size(), MSG_NOSIGNAL), static_cast<ssize_t>(line.size()));
        slow.push_back(fd);
    }
    std::atomic<bool> stop{false};
    std::thread trickle([&] {
        for (int round = 0; !stop && round < 100; ++round) {
            for (int fd : slow) ::send(fd, "X-Slow: 1\r\n", 11, MSG_NOSIGNAL);
            std::this_thread::sleep_for(100ms);
        }
    });
    std::this_thread::sleep_for(300ms);
    httplib::Client probe("127.0.0.1", api_->tcp_port());
    probe.set_connection_timeout(1, 0);
    probe.set_read_timeout(1, 0);
    const auto t0 = std::chrono::steady_clock::now();
    auto health = probe.Get("/v1/health");
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    stop = true;
    trickle.join();
    for (int fd : slow) ::close(fd);
    ASSERT_TRUE(health) << httplib::to_string(health.error()) << " after " << ms << " ms";
    EXPECT_EQ(health->status, 200);
    EXPECT_LT(ms, 1000.0);
}

class HttpApiProtectedReadsTest : public HttpApiTokenTest {
protected:
    void SetUp() override {
        ServerConfig config = TokenConfig();
        config.protect_reads = true;
        config.unix_socket_mode = "0600";
        StartApi(config);
    }
};

TEST_F(HttpApiProtectedReadsTest, GetsNeedTheTokenToo) {
    ExpectError(client_->Get("/v1/status"), 401, "UNAUTHORIZED");
    ExpectError(client_->Get("/v1/measurements/last"), 401, "UNAUTHORIZED");
    ExpectError(client_->Get("/metrics"), 401, "UNAUTHORIZED");
    auto ok = client_->Get("/v1/status", {{"Authorization", "Bearer s3cret"}});
    ASSERT_TRUE(ok);
    EXPECT_EQ(ok->status, 200);
    struct stat st {};
    ASSERT_EQ(::stat((dir_ / "boxd.sock").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u);
}

TEST(ServerConfigValidate, SocketModeAndProtectedReadsNameTheirKey) {
    ServerConfig c;
    c.unix_socket_mode = "0999";
    ASSERT_FALSE(c.Validate());
    EXPECT_NE(c.Validate().error().message.find("server.unix_socket_mode"), std::string::npos);
    c = {};
    c.protect_reads = true;
    ASSERT_FALSE(c.Validate());
    EXPECT_NE(c.Validate().error().message.find("server.protect_reads"), std::string::npos);
}

TEST(HttpApiBind, AnAddressInUseIsAnErrorNamingTheKey) {
    test::TempDir dir;
    auto store = MeasurementStore::Open(dir.path(), 5);
    ASSERT_TRUE(store);
    MeasurementService service(**store, std::make_shared<ScriptedStation>(), false);
    ServerConfig config;
    config.listen = "127.0.0.1:0";
    HttpApi first(config, service, **store, nullptr);
    ASSERT_TRUE(first.Start());
    config.listen = "127.0.0.1:" + std::to_string(first.tcp_port());
    HttpApi second(config, service, **store, nullptr);
    Status s = second.Start();
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("server.listen"), std::string::npos);
}

}  // namespace
}  // namespace boxd
