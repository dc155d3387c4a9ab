// GET /v1/openapi.json is honest: every route the server registers is described (and nothing
// else), every described route answers on a real socket, and real responses of the main routes
// validate against the document's schemas (Debian's python3-jsonschema, JSON Schema 2020-12).
#include "daemon/service/openapi_document.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "tests/support/http_api_fixture.h"
#include "tests/support/run_command.h"

namespace boxd {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using Route = std::pair<std::string, std::string>;  // method (lower case), OpenAPI path

// Returns every route registered with routes.Get/Post/... in the daemon's sources, its path
// pattern written as the document's template (a ([^/]+) capture is {id}).
std::set<Route> RegisteredRoutes() {
    static const std::regex call(
        R"re(routes\.(Get|Post|Put|Delete|Patch)\(\s*(?:R"\(((?:[^)]|\)(?!"))*)\)"|"([^"]*)"))re");
    std::set<Route> routes;
    for (const auto& entry : fs::directory_iterator(fs::path(BOXD_SOURCE_DIR) / "daemon/service")) {
        if (entry.path().extension() != ".cpp") continue;
        std::ifstream in(entry.path());
        std::stringstream text;
        text << in.rdbuf();
        const std::string source = text.str();
        for (std::sregex_iterator it(source.begin(), source.end(), call), end; it != end; ++it) {
            std::string method = (*it)[1];
            for (char& c : method) c = static_cast<char>(std::tolower(c));
            std::string path = (*it)[2].matched ? (*it)[2].str() : (*it)[3].str();
            path = std::regex_replace(path, std::regex(R"(\(\[\^/\]\+\))"), "{id}");
            path = std::regex_replace(path, std::regex(R"(\\\.)"), ".");
            routes.insert({method, path});
        }
    }
    return routes;
}

std::set<Route> DescribedRoutes(const json& doc) {
    std::set<Route> routes;
    for (const auto& [path, item] : doc.at("paths").items()) {
        for (const auto& [method, op] : item.items()) routes.insert({method, path});
    }
    return routes;
}

TEST(OpenApi, TheDocumentIsOpenApi31WithTheProjectsVersion) {
    const json doc = json::parse(OpenApiDocument());
    EXPECT_EQ(doc.at("openapi").get<std::string>().rfind("3.1", 0), 0u);
    EXPECT_EQ(doc.at("info").at("version"), BOXD_TEST_VERSION);
    for (const auto& [path, item] : doc.at("paths").items()) {
        for (const auto& [method, op] : item.items()) {
            EXPECT_TRUE(op.contains("summary")) << method << " " << path;
            EXPECT_TRUE(op.at("responses").contains("200")) << method << " " << path;
        }
    }
}

TEST(OpenApi, EveryRegisteredRouteIsDescribedAndNothingElse) {
    const std::set<Route> registered = RegisteredRoutes();
    ASSERT_GE(registered.size(), 10u) << "the source scan found too few routes";
    const std::set<Route> described = DescribedRoutes(json::parse(OpenApiDocument()));
    for (const Route& r : registered) {
        EXPECT_TRUE(described.count(r)) << "not described: " << r.first << " " << r.second;
    }
    for (const Route& r : described) {
        EXPECT_TRUE(registered.count(r)) << "described but not served: " << r.first << " "
                                         << r.second;
    }
}

class OpenApiServed : public test::HttpApiTest {
protected:
    // Keeps `res` to be validated as the response `status` of `method` `path` (a template).
    void Keep(const std::string& method, const std::string& path, const httplib::Result& res,
              int status) {
        ASSERT_TRUE(res) << method << " " << path;
        ASSERT_EQ(res->status, status) << method << " " << path << ": " << res->body;
        const fs::path file = dir_ / ("response" + std::to_string(manifest_.size()) + ".json");
        std::ofstream(file) << res->body;
        manifest_.push_back(
            {{"method", method}, {"path", path}, {"status", status}, {"file", file.string()}});
    }

    json manifest_ = json::array();
};

TEST_F(OpenApiServed, RealResponsesOfTheMainRoutesValidateAgainstTheirSchemas) {
    auto served = client_->Get("/v1/openapi.json");
    ASSERT_TRUE(served);
    ASSERT_EQ(served->status, 200);
    EXPECT_EQ(served->get_header_value("Content-Type"), "application/json");
    EXPECT_EQ(json::parse(served->body), json::parse(OpenApiDocument()));

    Keep("get", "/v1/health", client_->Get("/v1/health"), 200);
    Keep("get", "/v1/status", client_->Get("/v1/status"), 200);
    Keep("get", "/v1/measurements/{id}", client_->Get("/v1/measurements/last"), 404);
    Keep("post", "/v1/measure",
         client_->Post("/v1/measure?wait=1", R"({"parcel_id": "PKG-7"})", "application/json"),
         200);
    station_->refuse_next = true;
    Keep("post", "/v1/measure", client_->Post("/v1/measure?wait=1", "", "application/json"),
         200);
    station_->fail_next = true;
    Keep("post", "/v1/measure", client_->Post("/v1/measure?wait=1", "", "application/json"),
         500);
    Keep("post", "/v1/measure",
         client_->Post("/v1/measure", R"({"parcelId": "PKG-7"})", "application/json"), 400);
    WaitUntilIdle();
    station_->hold = true;
    Keep("post", "/v1/measure", client_->Post("/v1/measure", "", "application/json"), 202);
    Keep("get", "/v1/status", client_->Get("/v1/status"), 200);  // measuring, with progress
    Keep("post", "/v1/measure", client_->Post("/v1/measure", "", "application/json"), 409);
    station_->hold = false;
    WaitUntilIdle();
    Keep("get", "/v1/measurements", client_->Get("/v1/measurements?limit=10"), 200);
    Keep("get", "/v1/measurements", client_->Get("/v1/measurements?limit=0"), 400);
    Keep("get", "/v1/measurements/{id}", client_->Get("/v1/measurements/m-000001"), 200);
    Keep("get", "/v1/measurements/{id}", client_->Get("/v1/measurements/last"), 200);
    Keep("post", "/v1/calibrate",
         client_->Post("/v1/calibrate", R"({"reference_m": [0.4, 0.3, 0.2]})", "application/json"),
         200);
    Keep("post", "/v1/calibrate",
         client_->Post("/v1/calibrate", R"({"reference_m": [0.4, 0.3, 2]})", "application/json"),
         422);
    Keep("post", "/v1/calibrate",
         client_->Post("/v1/calibrate", R"({"reference_m": [0.4]})", "application/json"), 400);
    Keep("get", "/v1/calibration", client_->Get("/v1/calibration"), 200);

    const fs::path doc = dir_ / "openapi.json", manifest = dir_ / "manifest.json";
    std::ofstream(doc) << OpenApiDocument();
    std::ofstream(manifest) << manifest_.dump();
    const auto check = test::RunCommand(
        {"/usr/bin/python3", std::string(BOXD_SOURCE_DIR) + "/tests/support/openapi_validate.py",
         doc.string(), manifest.string()});
    EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

TEST_F(OpenApiServed, EveryDescribedRouteAnswersWithADescribedStatus) {
    ASSERT_EQ(client_->Post("/v1/measure?wait=1", "", "application/json")->status, 200);
    const json doc = json::parse(OpenApiDocument());
    for (const auto& [path, item] : doc.at("paths").items()) {
        const std::string real = std::regex_replace(path, std::regex(R"(\{id\})"), "m-000001");
        for (const auto& [method, op] : item.items()) {
            auto res = method == "get" ? client_->Get(real)
                                       : client_->Post(real, "{}", "application/json");
            ASSERT_TRUE(res) << method << " " << path;
            EXPECT_TRUE(op.at("responses").contains(std::to_string(res->status)))
                << method << " " << path << " answered " << res->status << ": " << res->body;
        }
    }
}

}  // namespace
}  // namespace boxd
