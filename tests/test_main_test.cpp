// Checks of tests/test_main.cpp: the scratch folder of a test process is its own, and both ways
// tests find a temporary folder (TMPDIR, TEST_TMPDIR) lead into it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace test_main_test {
namespace {

namespace fs = std::filesystem;

TEST(TestScratchFolder, IsPrivateToTheProcessAndSharedByBothLookups) {
  const fs::path by_tmpdir = fs::temp_directory_path();
  const fs::path by_gtest = fs::path(testing::TempDir());
  EXPECT_EQ(fs::canonical(by_tmpdir), fs::canonical(by_gtest));
  // mkdtemp's name: geomint_test_ and six random characters.
  const std::string name = fs::canonical(by_tmpdir).filename().string();
  EXPECT_EQ(name.rfind("geomint_test_", 0), 0U) << name;
  EXPECT_EQ(name.size(), std::string("geomint_test_XXXXXX").size()) << name;
  EXPECT_TRUE(fs::is_directory(by_tmpdir));
}

}  // namespace
}  // namespace test_main_test
