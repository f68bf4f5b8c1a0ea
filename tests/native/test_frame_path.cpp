// test_frame_path.cpp — sequence frame file names (cloudgen/frame_path.h).
// Exact string comparisons: the names are the CLI's protocol (docs/cli_protocol.md).
#include <gtest/gtest.h>

#include <climits>
#include <string>

#include "cloudgen/frame_path.h"

namespace {

struct Case {
  const char* pattern;
  long long frame;
  const char* expect;
};

TEST(FramePath, LastRunOfHashesIsTheFrame) {
  const Case cases[] = {
      {"a_##/f_####.vdb", 7, "a_##/f_0007.vdb"},  // the last run, not the first
      {"f_#.vdb", 0, "f_0.vdb"},
      {"f_##.vdb", 12345, "f_12345.vdb"},  // longer than the run: written whole
      {"f_###.vdb", -7, "f_-007.vdb"},
      {"#", 42, "42"},
      {"cloud.vdb", 3, "cloud_0003.vdb"},
      {"cloud.VDB", 123456, "cloud_123456.VDB"},
      {"dir.d/cloud", 3, "dir.d/cloud_0003"},  // a dot in a folder is no extension
      {"dir/.vdb", 1, "dir/.vdb_0001"},        // a leading dot neither
      {"", 1, "_0001"},
  };
  for (const Case& c : cases)
    EXPECT_EQ(cg::frame_path(c.pattern, c.frame), c.expect) << "pattern '" << c.pattern << "' frame " << c.frame;
}

TEST(FramePath, AnyRunLengthGivesDistinctNames) {
  // 32 or more '#' once went through a 32-byte buffer: every frame got the same name.
  for (int width : {31, 32, 33, 64, 300}) {
    const std::string pattern = "f_" + std::string(width, '#') + ".vdb";
    const std::string a = cg::frame_path(pattern, 1), b = cg::frame_path(pattern, 2);
    EXPECT_NE(a, b) << "width " << width;
    EXPECT_EQ(a.size(), pattern.size()) << "width " << width;
    EXPECT_EQ(a.substr(a.size() - 5), "1.vdb") << "width " << width;
  }
}

TEST(FramePath, ExtremeFrames) {
  EXPECT_EQ(cg::frame_path("f_#", LLONG_MIN), "f_-9223372036854775808");
  EXPECT_EQ(cg::frame_path("f_#", LLONG_MAX), "f_9223372036854775807");
}

}  // namespace
