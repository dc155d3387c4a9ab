// The operator page: GET / serves index.html of the web folder, GET /three.min.js the three.js
// of Debian's libjs-three. Nothing is downloaded at run time; a missing file is a 404 that says
// which file and which key.
#include <filesystem>

#include "daemon/service/http_response.h"
#include "daemon/service/http_routes.h"

namespace boxd {

namespace fs = std::filesystem;
using Request = httplib::Request;
using Response = httplib::Response;

namespace {

// The operator page's folder: server.web_dir, else the installed one (share/boxd/web beside the
// binary's bin/), else the source tree's daemon/web (a binary run from its build folder).
fs::path WebDir(const ServerConfig& config) {
    if (!config.web_dir.empty()) return config.web_dir;
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const fs::path installed = exe.parent_path().parent_path() / "share/boxd/web";
        if (fs::exists(installed / "index.html", ec)) return installed;
    }
    return BOXD_SOURCE_WEB_DIR;
}

void ServeFile(Response& res, const fs::path& path, const char* type, const char* key) {
    bool ok = false;
    std::string data = ReadFile(path, ok);
    if (!ok || data.empty()) {
        SetError(res, ErrorCode::kNotFound,
                 std::string("the operator page needs ") + path.string() + " (" + key + ")");
        return;
    }
    res.status = 200;
    res.set_header("Cache-Control", "no-cache");
    res.set_content(std::move(data), type);
}

}  // namespace

void AddPageRoutes(RouteTable& routes, const ApiContext& api) {
    const fs::path page = WebDir(api.config) / "index.html";
    const fs::path three = api.config.three_js;
    routes.Get("/", Guarded([page](const Request&, Response& res) {
                   ServeFile(res, page, "text/html; charset=utf-8", "server.web_dir");
               }));
    routes.Get("/three.min.js", Guarded([three](const Request&, Response& res) {
                   ServeFile(res, three, "application/javascript", "server.three_js");
               }));
}

}  // namespace boxd
