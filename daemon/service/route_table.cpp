#include "daemon/service/route_table.h"

#include <spdlog/fmt/ranges.h>

#include <algorithm>

namespace boxd {

void RouteTable::Get(const std::string& pattern, httplib::Server::Handler handler) {
    server_.Get(pattern, std::move(handler));
    routes_.emplace_back("GET", std::regex(pattern));
}

void RouteTable::Post(const std::string& pattern, httplib::Server::Handler handler) {
    server_.Post(pattern, std::move(handler));
    routes_.emplace_back("POST", std::regex(pattern));
}

std::string RouteTable::AllowedMethods(const std::string& path) const {
    std::vector<std::string> methods;
    for (const auto& [method, pattern] : routes_) {
        if (!std::regex_match(path, pattern)) continue;
        if (std::find(methods.begin(), methods.end(), method) != methods.end()) continue;
        methods.push_back(method);
        if (method == "GET") methods.push_back("HEAD");
    }
    return fmt::format("{}", fmt::join(methods, ", "));
}

}  // namespace boxd
