#include "pipeline/core/error_code.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

namespace boxd {
namespace {

// Every code of the one list, in declaration order.
std::vector<ErrorCode> AllCodes() {
    return {
#define BOXD_TEST_CODE(e, name, category) ErrorCode::e,
        BOXD_ERROR_CODES(BOXD_TEST_CODE)
#undef BOXD_TEST_CODE
    };
}

TEST(ErrorCode, NamesAreUniqueUpperSnakeCaseAndParseBack) {
    std::set<std::string> seen;
    for (ErrorCode code : AllCodes()) {
        const std::string name = ErrorCodeName(code);
        EXPECT_TRUE(seen.insert(name).second) << "duplicate " << name;
        for (char c : name) EXPECT_TRUE((c >= 'A' && c <= 'Z') || c == '_') << name;
        ASSERT_TRUE(ParseErrorCode(name).has_value()) << name;
        EXPECT_EQ(*ParseErrorCode(name), code);
    }
    EXPECT_FALSE(ParseErrorCode("INTERNAL").has_value());  // one spelling: INTERNAL_ERROR
    EXPECT_FALSE(ParseErrorCode("").has_value());
}

TEST(ErrorCode, HttpStatusAndExitCodeFollowTheCategory) {
    for (ErrorCode code : AllCodes()) {
        const int http = HttpStatusOf(code);
        const int exit = ExitCodeOf(code);
        switch (CategoryOf(code)) {
            case ErrorCategory::kBadInput:
                EXPECT_EQ(http, 400) << code;
                EXPECT_EQ(exit, 2) << code;
                break;
            case ErrorCategory::kNoDimension:
                EXPECT_EQ(exit, 3) << code;
                break;
            case ErrorCategory::kCalibrationRefused:
                EXPECT_EQ(http, 422) << code;
                EXPECT_EQ(exit, 2) << code;
                break;
            case ErrorCategory::kConflict:
                EXPECT_EQ(http, 409) << code;
                break;
            case ErrorCategory::kNotFound:
                EXPECT_EQ(http, 404) << code;
                break;
            case ErrorCategory::kUnavailable:
                EXPECT_EQ(http, 503) << code;
                break;
            default:
                break;
        }
        EXPECT_TRUE(http >= 400 && http <= 599) << code;
        EXPECT_TRUE(exit >= 1 && exit <= 3) << code;
    }
    // The SPEC's no-dimension codes are refusals, device faults are not.
    EXPECT_EQ(CategoryOf(ErrorCode::kNoObject), ErrorCategory::kNoDimension);
    EXPECT_EQ(CategoryOf(ErrorCode::kObjectMoved), ErrorCategory::kNoDimension);
    EXPECT_EQ(CategoryOf(ErrorCode::kTurntableError), ErrorCategory::kDevice);
    EXPECT_EQ(HttpStatusOf(ErrorCode::kBusy), 409);
    EXPECT_EQ(ExitCodeOf(ErrorCode::kInternal), 1);
}

TEST(ErrorCode, ReachesJsonAndStreamsAsItsName) {
    nlohmann::json j = {{"code", ErrorCode::kObjectTooLarge}};
    EXPECT_EQ(j["code"], "OBJECT_TOO_LARGE");
    std::ostringstream os;
    os << ErrorCode::kStorageError;
    EXPECT_EQ(os.str(), "STORAGE_ERROR");
}

}  // namespace
}  // namespace boxd
