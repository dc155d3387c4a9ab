#pragma once
// ExpectError: a failed Result with the expected error code (header-only test helper).

#include <gtest/gtest.h>

#include "pipeline/core/result.h"

namespace boxd::test {

// Expects `r` to have failed with `code`.
template <typename T>
void ExpectError(const Result<T>& r, ErrorCode code) {
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, code) << r.error().message;
}

}  // namespace boxd::test
