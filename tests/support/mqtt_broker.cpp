#include "tests/support/mqtt_broker.h"

#include <arpa/inet.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <thread>

namespace boxd::test {

MqttBroker::MqttBroker(const std::filesystem::path& dir, int port, bool persistence)
    : dir_(dir), port_(port != 0 ? port : FreePort()) {
    std::filesystem::create_directories(dir_);
    const auto conf = dir_ / "mosquitto.conf";
    std::ofstream out(conf);
    out << "listener " << port_ << " 127.0.0.1\nallow_anonymous true\n";
    // Started as root, mosquitto would switch to the `mosquitto` user and lose the test's folder.
    if (const passwd* me = ::getpwuid(::getuid())) out << "user " << me->pw_name << "\n";
    if (persistence) {
        out << "persistence true\npersistence_location " << dir_.string() << "/\n";
    }
    out.close();
    process_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{"mosquitto", "-c", conf.string()}, dir_ / "mosquitto.log");
}

MqttBroker::~MqttBroker() { Stop(); }

bool MqttBroker::WaitReady(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
        if (!process_ || !process_->Running()) return false;
        const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(static_cast<uint16_t>(port_));
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
        ::close(fd);
        if (ok) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
}

void MqttBroker::Stop() {
    if (process_) process_->Terminate();
    process_.reset();
}

MqttSubscriber::MqttSubscriber(int port, const std::string& topic, const std::string& client_id,
                               bool clean_session)
    : topic_(topic) {
    mosquitto_lib_init();
    client_ = mosquitto_new(client_id.empty() ? nullptr : client_id.c_str(), clean_session, this);
    mosquitto_connect_callback_set(client_, [](mosquitto* m, void* self, int rc) {
        if (rc == 0) {
            mosquitto_subscribe(m, nullptr, static_cast<MqttSubscriber*>(self)->topic_.c_str(), 1);
        }
    });
    mosquitto_subscribe_callback_set(client_, [](mosquitto*, void* obj, int, int, const int*) {
        auto* self = static_cast<MqttSubscriber*>(obj);
        std::lock_guard lock(self->mutex_);
        self->subscribed_ = true;
        self->changed_.notify_all();
    });
    mosquitto_message_callback_set(
        client_, [](mosquitto*, void* obj, const mosquitto_message* m) {
            auto* self = static_cast<MqttSubscriber*>(obj);
            std::lock_guard lock(self->mutex_);
            self->messages_.push_back(
                {m->topic, std::string(static_cast<const char*>(m->payload), m->payloadlen),
                 m->retain});
            self->changed_.notify_all();
        });
    mosquitto_connect(client_, "127.0.0.1", port, 30);
    mosquitto_loop_start(client_);
}

MqttSubscriber::~MqttSubscriber() {
    Disconnect();
    mosquitto_destroy(client_);
}

void MqttSubscriber::Disconnect() {
    if (client_ == nullptr) return;
    mosquitto_disconnect(client_);
    mosquitto_loop_stop(client_, false);
}

bool MqttSubscriber::WaitSubscribed(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [this] { return subscribed_; });
}

std::vector<MqttMessage> MqttSubscriber::WaitFor(const std::string& topic, std::size_t count,
                                                 std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    std::vector<MqttMessage> out;
    changed_.wait_for(lock, timeout, [&] {
        out.clear();
        for (const MqttMessage& m : messages_) {
            if (m.topic == topic) out.push_back(m);
        }
        return out.size() >= count;
    });
    return out;
}

}  // namespace boxd::test
