#pragma once
// Reads a Prometheus text exposition (format 0.0.4) the way a scraper would: every line is a
// comment (# HELP / # TYPE name ...) or a sample `name{labels} value`; anything else fails the
// test that reads it.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <sstream>
#include <string>

namespace boxd::test {

// Returns the samples of `text` keyed by `name{labels}` exactly as written (`name` without
// labels); adds a test failure for each line that is neither a sample nor a HELP/TYPE comment.
inline std::map<std::string, double> ParsePrometheus(const std::string& text) {
    static const std::regex sample(
        R"(^([a-zA-Z_:][a-zA-Z0-9_:]*(\{([a-zA-Z_][a-zA-Z0-9_]*="[^"\\]*",?)*\})?) (-?[0-9][0-9.e+-]*|[+-]Inf|NaN)$)");
    static const std::regex comment(R"(^# (HELP|TYPE) [a-zA-Z_:][a-zA-Z0-9_:]* .+$)");
    std::map<std::string, double> out;
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) {
        std::smatch m;
        if (std::regex_match(line, m, sample)) {
            EXPECT_EQ(out.count(m[1]), 0u) << "sample written twice: " << line;
            out[m[1]] = std::stod(m[4]);
        } else {
            EXPECT_TRUE(std::regex_match(line, comment)) << "not a sample or comment: " << line;
        }
    }
    return out;
}

}  // namespace boxd::test
