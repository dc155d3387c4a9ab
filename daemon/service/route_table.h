#pragma once
// RouteTable: registers the API's routes on a cpp-httplib server and remembers them, so that a
// request for a known path with a method it does not serve is answered 405 with an Allow header
// (RFC 9110 15.5.6) instead of httplib's 404.

#include <regex>
#include <string>
#include <utility>
#include <vector>

// Eigen/Core before httplib.h (see http_response.h).
// clang-format off
#include <Eigen/Core>
#include <httplib.h>
// clang-format on

namespace boxd {

class RouteTable {
public:
    explicit RouteTable(httplib::Server& server) : server_(server) {}

    // Registers `handler` for GET (and so HEAD, which httplib answers with the GET handler) of
    // the paths `pattern` matches whole.
    void Get(const std::string& pattern, httplib::Server::Handler handler);
    // Registers `handler` for POST of the paths `pattern` matches whole.
    void Post(const std::string& pattern, httplib::Server::Handler handler);

    // Returns the methods registered for `path` as an Allow header lists them ("GET, HEAD"), or
    // "" when no route has that path.
    std::string AllowedMethods(const std::string& path) const;

private:
    httplib::Server& server_;
    std::vector<std::pair<std::string, std::regex>> routes_;  // method, pattern
};

}  // namespace boxd
