// The command line's help texts are a contract (docs/CLI.md): `geomint --help` and every
// `geomint <verb> --help` must equal tests/golden/help/<verb>.txt byte for byte, with exit 0.
// After an intended change of a help text, regenerate the golden files from the new binary:
//   mkdir -p /tmp/gbin && ln -sf "$PWD/build/geomint" /tmp/gbin/geomint &&
//   PATH=/tmp/gbin:$PATH geomint --help > tests/golden/help/geomint.txt &&
//   for v in list run order score sweep merge slurm reference modes gate report perf-compare; do
//     PATH=/tmp/gbin:$PATH geomint $v --help > tests/golden/help/$v.txt; done
// (CLI11 prints argv[0] in its Usage line, so the program runs as plain `geomint`, via PATH).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "harness/paths.hpp"

namespace geomint {
namespace cli_help_test {
namespace {

namespace fs = std::filesystem;

struct Captured {
  int exit_code = -1;
  std::string out;  // stdout alone: help goes there
};

// Runs `geomint ARGUMENTS` with argv[0] = "geomint" (a symlink named geomint first on PATH).
Captured run_as_geomint(const fs::path& folder, const std::string& arguments) {
  const std::string command =
      "PATH=" + shell_quoted(folder.string()) + ":\"$PATH\" geomint " + arguments + " 2>/dev/null";
  FILE* pipe = popen(command.c_str(), "r");
  Captured captured;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) {
    captured.out.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  captured.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return captured;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(CliHelp, EveryHelpTextEqualsItsGoldenFile) {
  const fs::path folder =
      fs::temp_directory_path() / ("geomint help (" + std::to_string(getpid()) + ")");
  fs::create_directories(folder);
  fs::remove(folder / "geomint");
  fs::create_symlink(GEOMINT_BINARY, folder / "geomint");
  const fs::path golden = fs::path(GEOMINT_SOURCE_DIR) / "tests" / "golden" / "help";
  int compared = 0;
  for (const auto& entry : fs::directory_iterator(golden)) {
    const std::string verb = entry.path().stem().string();
    const std::string arguments = verb == "geomint" ? "--help" : verb + " --help";
    const Captured help = run_as_geomint(folder, arguments);
    EXPECT_EQ(help.exit_code, 0) << "geomint " << arguments;
    EXPECT_EQ(help.out, read_text(entry.path()))
        << "geomint " << arguments << " differs from " << entry.path()
        << " (regeneration: see the top of tests/cli_help_test.cpp)";
    ++compared;
  }
  fs::remove_all(folder);
  // geomint.txt and one file per verb of `geomint --help`.
  const std::string top = read_text(golden / "geomint.txt");
  const std::string listed = top.substr(top.find("Subcommands:"));
  int verbs = 0;
  std::istringstream lines(listed);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("  ", 0) != 0) continue;
    const std::string verb = line.substr(2, line.find(' ', 2) - 2);
    EXPECT_TRUE(fs::exists(golden / (verb + ".txt"))) << "no golden help for verb " << verb;
    ++verbs;
  }
  EXPECT_EQ(compared, verbs + 1);
}

// The options of a help text: one string per option (continuation lines joined), from the
// "Options:" section.
std::vector<std::string> option_entries(const std::string& help) {
  std::vector<std::string> entries;
  std::istringstream lines(help);
  bool inside = false;
  for (std::string line; std::getline(lines, line);) {
    if (line == "Options:") {
      inside = true;
    } else if (line.empty()) {
      inside = false;
    } else if (inside && line.rfind("  -", 0) == 0) {
      entries.push_back(line);
    } else if (inside && !entries.empty()) {
      entries.back() += " " + line;
    }
  }
  return entries;
}

// Every verb's --help shows the default of each option that takes a value and is not required,
// and leaves the exit codes to `geomint --help` (printed once there, not 520 characters per verb).
TEST(CliHelp, EveryVerbShowsItsDefaultsAndNotTheExitCodes) {
  const fs::path folder =
      fs::temp_directory_path() / ("geomint_help_defaults_" + std::to_string(getpid()));
  fs::create_directories(folder);
  fs::remove(folder / "geomint");
  fs::create_symlink(GEOMINT_BINARY, folder / "geomint");
  const Captured top = run_as_geomint(folder, "--help");
  EXPECT_NE(top.out.find("Exit codes: 0 ok"), std::string::npos) << top.out;
  std::istringstream verbs(top.out.substr(top.out.find("Subcommands:")));
  const std::regex takes_value(R"(^\s+\S+ [A-Z]+(:\S*)?( |$).*)");
  int options = 0;
  for (std::string line; std::getline(verbs, line);) {
    if (line.rfind("  ", 0) != 0) continue;
    const std::string verb = line.substr(2, line.find(' ', 2) - 2);
    const Captured help = run_as_geomint(folder, verb + " --help");
    EXPECT_EQ(help.out.find("Exit codes: 0 ok"), std::string::npos) << verb << ":\n" << help.out;
    for (const std::string& entry : option_entries(help.out)) {
      if (!std::regex_match(entry, takes_value) || entry.find("REQUIRED") != std::string::npos) {
        continue;
      }
      EXPECT_NE(entry.find("default"), std::string::npos) << verb << ": " << entry;
      ++options;
    }
  }
  EXPECT_GT(options, 20);
  // The defaults no help text used to mention.
  for (const auto& [verb, option, shown] : {std::tuple{"sweep", "--jobs", "(default: 1)"},
                                            {"run", "--timing-repeats", "(default: 3)"},
                                            {"run", "--every", "(default: 1)"},
                                            {"order", "--levels", "(default: 6)"},
                                            {"slurm", "--shards", "default"}}) {
    const Captured help = run_as_geomint(folder, std::string(verb) + " --help");
    bool found = false;
    for (const std::string& entry : option_entries(help.out)) {
      if (entry.rfind(std::string("  ") + option + " ", 0) != 0) continue;
      found = true;
      EXPECT_NE(entry.find(shown), std::string::npos) << verb << ": " << entry;
    }
    EXPECT_TRUE(found) << verb << " " << option << ":\n" << help.out;
  }
  fs::remove_all(folder);
}

}  // namespace
}  // namespace cli_help_test
}  // namespace geomint
