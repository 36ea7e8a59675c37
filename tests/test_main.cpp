// main() of every geomint test executable (docs/TESTING.md "Testing"): each test process writes its
// scratch files in a folder of its own, so tests that `ctest -j` runs at the same time never share
// a fixed path such as /tmp/geomint_sweep_tables (two of them once removed each other's tables).
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  // The parent stays whatever TMPDIR names (ctest sets <build>/test-tmp, tests/slow_tests.cmake).
  std::error_code error;
  fs::path parent = fs::temp_directory_path(error);
  if (error) parent = "/tmp";
  std::string folder = (parent / "geomint_test_XXXXXX").string();
  if (::mkdtemp(folder.data()) == nullptr) {
    std::perror(("geomint test main: cannot create a scratch folder in " + parent.string()).c_str());
    return 1;
  }
  // std::filesystem::temp_directory_path() reads TMPDIR, testing::TempDir() reads TEST_TMPDIR;
  // the geomint processes the tests start inherit both.
  ::setenv("TMPDIR", folder.c_str(), 1);
  ::setenv("TEST_TMPDIR", folder.c_str(), 1);
  testing::InitGoogleTest(&argc, argv);
  const int status = RUN_ALL_TESTS();
  // GEOMINT_KEEP_TEST_TMPDIR=1 keeps the folder to look at what a failing test wrote.
  const char* keep = std::getenv("GEOMINT_KEEP_TEST_TMPDIR");
  if (keep != nullptr && std::string(keep) == "1") {
    std::fprintf(stderr, "geomint test main: scratch files kept in %s\n", folder.c_str());
  } else {
    fs::remove_all(folder, error);
  }
  return status;
}
