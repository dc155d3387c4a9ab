#include "pipeline/io/ply_writer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "tests/support/expect_error.h"
#include "tests/support/temp_dir.h"

namespace boxd {
namespace {

using test::ExpectError;

std::string ReadAll(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(WritePly, HeaderThenLittleEndianFloatTriples) {
    test::TempDir dir;
    const Points pts = {{0.1f, -0.2f, 0.3f}, {1.5f, 2.25f, -3.0f}};
    ASSERT_TRUE(WritePly(dir / "cloud.ply", pts).ok());
    const std::string data = ReadAll(dir / "cloud.ply");
    const std::string header =
        "ply\nformat binary_little_endian 1.0\ncomment boxd fused cloud, table frame, metres\n"
        "element vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    ASSERT_EQ(data.size(), header.size() + 2 * 3 * sizeof(float));
    EXPECT_EQ(data.substr(0, header.size()), header);
    float xyz[6];
    std::memcpy(xyz, data.data() + header.size(), sizeof(xyz));
    for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(xyz[i], pts[0][i]);  // bit-exact round trip
        EXPECT_EQ(xyz[3 + i], pts[1][i]);
    }
}

TEST(WritePly, EmptyCloudHasZeroVertices) {
    test::TempDir dir;
    ASSERT_TRUE(WritePly(dir / "empty.ply", {}).ok());
    const std::string data = ReadAll(dir / "empty.ply");
    EXPECT_NE(data.find("element vertex 0\n"), std::string::npos);
    EXPECT_EQ(data.substr(data.size() - 11), "end_header\n");
}

TEST(WritePly, UnwritablePathIsAnIoError) {
    test::TempDir dir;
    ExpectError(WritePly(dir / "missing" / "cloud.ply", {{0.0f, 0.0f, 0.0f}}), ErrorCode::kIoError);
}

}  // namespace
}  // namespace boxd
