// The operator page: GET / serves index.html of the web folder, GET /page.css, /page.js and
// /cloud_view.js its layout and scripts, GET /three.min.js the three.js of Debian's libjs-three.
// Nothing is downloaded at run time; a missing file is a 404 that says which file and which key.
// Each answer carries an ETag (the file's size and modification time, as common web servers
// make it) and Cache-Control: no-cache: a browser revalidates on every load and a file that did
// not change costs a 304 without a body (three.js alone is 850 KB).
#include <cstdio>
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

// Returns the ETag of the file at `path` ("\"<size hex>-<mtime ns hex>\""), or "" when it cannot
// be read.
std::string ETagOf(const fs::path& path) {
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec) return "";
    const auto mtime = fs::last_write_time(path, ec);
    if (ec) return "";
    char tag[64];
    std::snprintf(tag, sizeof tag, "\"%llx-%llx\"", static_cast<unsigned long long>(size),
                  static_cast<unsigned long long>(mtime.time_since_epoch().count()));
    return tag;
}

// Returns whether the request's If-None-Match names `etag` (or is "*").
bool StillFresh(const Request& req, const std::string& etag) {
    const std::string asked = req.get_header_value("If-None-Match");
    return !etag.empty() && (asked == "*" || asked.find(etag) != std::string::npos);
}

void ServeFile(const Request& req, Response& res, const fs::path& path, const char* type,
               const char* key) {
    const std::string etag = ETagOf(path);
    res.set_header("Cache-Control", "no-cache");
    if (StillFresh(req, etag)) {
        res.status = 304;
        res.set_header("ETag", etag);
        return;
    }
    bool ok = false;
    std::string data = ReadFile(path, ok);
    if (!ok || data.empty()) {
        SetError(res, ErrorCode::kNotFound,
                 std::string("the operator page needs ") + path.string() + " (" + key + ")");
        return;
    }
    res.status = 200;
    if (!etag.empty()) res.set_header("ETag", etag);
    res.set_content(std::move(data), type);
}

// The handler that serves the file at `path`.
httplib::Server::Handler Static(fs::path path, const char* type, const char* key) {
    return Guarded([path = std::move(path), type, key](const Request& req, Response& res) {
        ServeFile(req, res, path, type, key);
    });
}

}  // namespace

void AddPageRoutes(RouteTable& routes, const ApiContext& api) {
    const fs::path web = WebDir(api.config);
    routes.Get("/", Static(web / "index.html", "text/html; charset=utf-8", "server.web_dir"));
    routes.Get("/page.css", Static(web / "page.css", "text/css; charset=utf-8", "server.web_dir"));
    routes.Get("/page.js",
               Static(web / "page.js", "text/javascript; charset=utf-8", "server.web_dir"));
    routes.Get("/cloud_view.js",
               Static(web / "cloud_view.js", "text/javascript; charset=utf-8", "server.web_dir"));
    routes.Get("/three.min.js",
               Static(api.config.three_js, "application/javascript", "server.three_js"));
}

}  // namespace boxd
