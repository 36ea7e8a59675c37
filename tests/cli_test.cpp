// Command-line contract (docs/DESIGN.md §4): good input works, a failed run is a row with exit 1,
// series are streamed, the method and problem tables of docs/ match `geomint list`. Bad input (exit
// 2, a message naming what was wrong, no output file) is the registry of tests/bad_input_test.cpp.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <vector>

#include "harness/paths.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace cli_test {
namespace {

namespace fs = std::filesystem;

struct Outcome {
  int exit_code;
  std::string output;  // stdout and stderr
};

Outcome geomint_shell(const std::string& line) {
  const std::string command = "(" + line + ") 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  std::array<char, 4096> buffer;
  while (size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

// `arguments` is shell text: a path in it is written as shell_quoted(path), since the build folder
// (and so the binary and the scratch files) may have a space or parentheses in its path.
Outcome geomint(const std::string& arguments) {
  return geomint_shell(shell_quoted(GEOMINT_BINARY) + " " + arguments);
}

// One geomint run with its output discarded: exit code and peak resident set size (KiB, from
// wait4's rusage of that process alone). Arguments are shell text split as bash splits it
// (shell_words), so a path is passed as shell_quoted(path).
struct Footprint {
  int exit_code = -1;
  long peak_rss_kib = 0;
};
Footprint geomint_footprint(const std::string& arguments) {
  std::vector<std::string> words{GEOMINT_BINARY};
  for (const std::string& word : shell_words(arguments)) words.push_back(word);
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    execv(argv[0], argv.data());
    _exit(127);
  }
  Footprint footprint;
  int status = 0;
  struct rusage usage {};
  if (pid > 0 && wait4(pid, &status, 0, &usage) == pid) {
    footprint.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    footprint.peak_rss_kib = usage.ru_maxrss;
  }
  return footprint;
}

// The scratch folder's name has a space and parentheses, as a clone's path may (say
// "/home/me/my code (2)/geomint"): every command line below must quote the paths it names.
fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "geomint cli test (x)";
  fs::create_directories(dir);
  fs::remove_all(dir / name);
  return dir / name;
}

// Bad input (exit 2, a message naming it, no file) is covered case by case in
// tests/bad_input_test.cpp.

// The installed package's version file and `geomint --version` say the same (CMake's
// PROJECT_VERSION, docs/VERIFY.md "Verify your own integrator"); exit 0 without a command.
TEST(Cli, VersionPrintsTheProjectVersion) {
  const Outcome outcome = geomint("--version");
  EXPECT_EQ(outcome.exit_code, 0) << outcome.output;
  EXPECT_EQ(outcome.output.rfind(std::string("geomint ") + GEOMINT_VERSION + " (", 0), 0u)
      << outcome.output;
}

TEST(Cli, RunWritesOneRowWithProvenance) {
  const fs::path out = scratch("run.csv");
  const Outcome outcome = geomint(
      "run --problem harmonic --method stormer_verlet --dt 0.1 "
      "--t-end 1 --timing-repeats 1 --out " +
      shell_quoted(out.string()));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.output;
  std::ifstream in(out);
  std::string line, header;
  int provenance = 0, data = 0;
  while (std::getline(in, line)) {
    if (line.rfind("# ", 0) == 0) {
      ++provenance;
    } else if (header.empty()) {
      header = line;
    } else {
      ++data;
    }
  }
  EXPECT_GE(provenance, 5);
  EXPECT_EQ(data, 1);
  EXPECT_NE(header.find("energy_err_max"), std::string::npos);
  EXPECT_NE(header.find("wall_s"), std::string::npos);
  // Harmonic has no angular momentum: the column is left out, not written as zero.
  EXPECT_EQ(header.find("angular_momentum_err_max"), std::string::npos);
}

TEST(Cli, SeriesHasStateColumnsAndEndsAtTEnd) {
  const fs::path series = scratch("series.csv");
  const Outcome outcome = geomint(
      "run --problem kepler --method rk4 --dt 0.1 --t-end 1.05 "
      "--timing-repeats 0 --series " +
      shell_quoted(series.string()) + " --every 3");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.output;
  std::ifstream in(series);
  std::string line, header, last;
  while (std::getline(in, line)) {
    if (line.rfind("#", 0) == 0) continue;
    if (header.empty()) {
      header = line;
    } else {
      last = line;
    }
  }
  EXPECT_EQ(header, "t,energy,angular_momentum_0,q_0,q_1,p_0,p_1");
  EXPECT_EQ(last.substr(0, last.find(',')), "1.05");
}

TEST(Cli, FailedRunIsARowWithExitOne) {
  // Explicit Euler on a stiff harmonic oscillator at hω = 10 blows up.
  const Outcome outcome = geomint(
      "run --problem harmonic:omega=100 --method explicit_euler "
      "--dt 0.1 --t-end 100 --timing-repeats 0");
  EXPECT_EQ(outcome.exit_code, 1) << outcome.output;
  EXPECT_NE(outcome.output.find(",diverged,"), std::string::npos) << outcome.output;
}

// `modes` prints one row per normal mode (ω, ω̃, relative error, ρ); a nonlinear problem or a
// method without a linearised step is bad input naming the reason. Störmer–Verlet on the harmonic
// oscillator at hω = 0.5: ω̃ = (2/h) arcsin(hω/2) = 1.0107…
TEST(Cli, ModesPrintsOneRowPerModeAndRejectsNonlinearProblems) {
  const Outcome outcome = geomint("modes --problem harmonic --method stormer_verlet --dt 0.5");
  EXPECT_EQ(outcome.exit_code, 0) << outcome.output;
  EXPECT_NE(outcome.output.find("mode,omega,omega_discrete,freq_err_rel,rho\n1,1,1.0107"),
            std::string::npos)
      << outcome.output;
  const Outcome nonlinear = geomint("modes --problem pendulum --method stormer_verlet --dt 0.1");
  EXPECT_EQ(nonlinear.exit_code, 2) << nonlinear.output;
  EXPECT_NE(nonlinear.output.find("not a linear problem"), std::string::npos) << nonlinear.output;
  EXPECT_EQ(geomint("modes --problem harmonic --method cvode_bdf --dt 0.1").exit_code, 2);
}

// --initial appends the spec key initial=FILE: the row's problem names the file, and a file of
// the wrong length is exit 2 naming the problem's n, for run and order alike.
// A program built on run_main (harness/run_main.hpp) names itself in its messages: argv[0]
// without its directories, here a symlink to geomint called my_sim.
TEST(Cli, MessagesStartWithTheProgramsOwnName) {
  const fs::path folder =
      fs::temp_directory_path() / ("geomint program name (" + std::to_string(getpid()) + ")");
  fs::create_directories(folder);
  const fs::path alias = folder / "my_sim";
  fs::remove(alias);
  fs::create_symlink(GEOMINT_BINARY, alias);
  const auto run = [&](const std::string& arguments) {
    return geomint_shell(shell_quoted(alias.string()) + " " + arguments);
  };
  const Outcome unknown = run("bogus");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_EQ(unknown.output.rfind("my_sim: error: unknown command 'bogus'", 0), 0u)
      << unknown.output;
  EXPECT_NE(unknown.output.find("see my_sim --help"), std::string::npos) << unknown.output;
  const Outcome bad = run("run --problem nope --method rk4");
  EXPECT_EQ(bad.output.rfind("my_sim: error: unknown problem 'nope'", 0), 0u) << bad.output;
  const Outcome failed =
      run("run --problem pendulum:theta0=3 --method implicit_euler:max_iter=1 --dt 2 --t-end 4");
  EXPECT_EQ(failed.exit_code, 1);
  EXPECT_NE(failed.output.find("my_sim: run failed: newton_max_iter"), std::string::npos)
      << failed.output;
  EXPECT_EQ(geomint("bogus").output.rfind("geomint: error: unknown command", 0), 0u);
  fs::remove_all(folder);
}

TEST(Cli, InitialStateFileStartsTheRunAndIsChecked) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string good = (dir / "geomint_cli_initial.csv").string();
  const std::string bad = (dir / "geomint_cli_initial_bad.csv").string();
  std::ofstream(good) << "q,v\n0.3,0\n";
  std::ofstream(bad) << "1,0\n2,0\n";
  const Outcome ran = geomint(
      "run --problem harmonic --method stormer_verlet --t-end 1 "
      "--timing-repeats 0 --initial " +
      shell_quoted(good));
  EXPECT_EQ(ran.exit_code, 0) << ran.output;
  EXPECT_NE(ran.output.find("harmonic:initial=" + good + ","), std::string::npos) << ran.output;
  for (const std::string command : {"run --problem spring_chain:n=4 --method stormer_verlet",
                                    "order --problem spring_chain:n=4 --method stormer_verlet "
                                    "--dt 0.1 --t-end 1"}) {
    const Outcome rejected = geomint(command + " --initial " + shell_quoted(bad));
    EXPECT_EQ(rejected.exit_code, 2) << rejected.output;
    EXPECT_NE(rejected.output.find("n = 4"), std::string::npos) << rejected.output;
  }
  std::filesystem::remove(good);
  std::filesystem::remove(bad);
}

TEST(Cli, DivergeFactorZeroLetsADivergingRunFinish) {
  // Explicit Euler at h = 0.1 multiplies the energy by 1.01 per step: 9e12 at t = 300.
  const std::string run =
      "run --problem harmonic --method explicit_euler --dt 0.1 --t-end 300 --timing-repeats 0";
  const Outcome stopped = geomint(run);
  EXPECT_EQ(stopped.exit_code, 1) << stopped.output;
  EXPECT_NE(stopped.output.find(",diverged,"), std::string::npos) << stopped.output;
  const Outcome finished = geomint(run + " --diverge-factor 0");
  EXPECT_EQ(finished.exit_code, 0) << finished.output;
  EXPECT_NE(finished.output.find(",ok,"), std::string::npos) << finished.output;
}

// The series is streamed to its file while the run goes, not held in memory: 1e4 step points
// of 128 state values (27 MB of text) under a 45 MB address-space limit (a tiny run needs
// < 20 MB). Before, the whole text was one growing string and the run died with bad_alloc.
TEST(Cli, SeriesIsStreamedNotHeldInMemory) {
  // AddressSanitizer's quarantine keeps freed blocks resident, so peak memory does not measure
  // what the program holds; the Release suite runs this check.
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's quarantine inflates the resident set";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  GTEST_SKIP() << "AddressSanitizer's quarantine inflates the resident set";
#endif
#endif
  // The same run for 1 and for 100 time units: the long one writes a > 25 MB series, so a series
  // held in memory would add > 25 MB to the peak; streamed, the peaks differ by buffers only.
  // (A peak-memory comparison, not `ulimit -v`: the optimised BLAS reserves address space at
  // start-up, which says nothing about what the run holds.)
  const std::string run =
      "run --problem spring_chain:n=64 --method stormer_verlet --dt 0.01 --timing-repeats 0 ";
  const fs::path short_series = scratch("streamed_short.csv");
  const fs::path series = scratch("streamed.csv");
  const Footprint baseline =
      geomint_footprint(run + "--t-end 1 --series " + shell_quoted(short_series.string()));
  const Footprint streamed =
      geomint_footprint(run + "--t-end 100 --series " + shell_quoted(series.string()));
  ASSERT_EQ(baseline.exit_code, 0);
  ASSERT_EQ(streamed.exit_code, 0);
  const auto series_kib = static_cast<long>(fs::file_size(series) / 1024);
  EXPECT_GT(series_kib, 25'000);
  EXPECT_LT(streamed.peak_rss_kib - baseline.peak_rss_kib, series_kib / 5)
      << "peak " << streamed.peak_rss_kib << " KiB against " << baseline.peak_rss_kib
      << " KiB for a series of " << series_kib << " KiB";
  fs::remove(series);
  fs::remove(short_series);
}

// The generated tables live in the catalogues: methods in docs/METHODS.md, problems in
// docs/PROBLEMS.md.
std::string table_file(const std::string& marker) {
  return std::string(GEOMINT_SOURCE_DIR) +
         (marker == "methods" ? "/docs/METHODS.md" : "/docs/PROBLEMS.md");
}

std::set<std::string> readme_table_names(const std::string& marker) {
  std::ifstream in(table_file(marker));
  std::string line;
  bool inside = false;
  std::set<std::string> names;
  const std::regex row(R"(^\| `([a-z0-9_]+)`)");
  while (std::getline(in, line)) {
    if (line.find("<!-- " + marker + ":begin -->") != std::string::npos) inside = true;
    if (line.find("<!-- " + marker + ":end -->") != std::string::npos) inside = false;
    std::smatch match;
    if (inside && std::regex_search(line, match, row)) names.insert(match[1]);
  }
  return names;
}

TEST(Cli, GateExitsZeroOnPassOneOnFailTwoOnBadInput) {
  const std::string root = GEOMINT_SOURCE_DIR;
  const std::string results = shell_quoted(root + "/results/fig1_pendulum/summary.csv");
  const fs::path passing = scratch("passing_gates.toml");
  std::ofstream(passing) << "[[gate]]\nname = \"fig1 runs\"\ncolumn = \"status\"\nequals = "
                            "\"ok\"\n";
  const Outcome passed = geomint("gate " + shell_quoted(passing.string()) + " " + results);
  EXPECT_EQ(passed.exit_code, 0) << passed.output;
  const fs::path failing = scratch("failing_gates.toml");
  std::ofstream(failing) << "[[gate]]\nname = \"too strict\"\nwhere = { method = "
                            "\"stormer_verlet\", label = \"short\" }\ncolumn = "
                            "\"energy_err_max\"\nmax = 1e-9\n";
  const Outcome failed = geomint("gate " + shell_quoted(failing.string()) + " " + results);
  EXPECT_EQ(failed.exit_code, 1) << failed.output;
  EXPECT_NE(failed.output.find("FAIL too strict"), std::string::npos) << failed.output;
  const fs::path malformed = scratch("malformed_gates.toml");
  std::ofstream(malformed) << "[[gate]]\nname = \"x\"\ncolumn = \"status\"\n";
  const Outcome bad = geomint("gate " + shell_quoted(malformed.string()) + " " + results);
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("min"), std::string::npos) << bad.output;
  EXPECT_EQ(geomint("gate " + shell_quoted(failing.string()) + " /nonexistent.csv").exit_code, 2);
}

// A scene's gates beside it (docs/GATING.md "Where gates live"): `geomint gate FOLDER` checks
// FOLDER/gates.toml on FOLDER's tables, and a scene among the results that no gate applies to is
// named on stderr (it has no gates file) rather than passing as zero gates.
TEST(Cli, GateFindsASceneFoldersOwnGatesAndNamesScenesWithout) {
  const fs::path root = scratch("own_gates");
  fs::remove_all(root);
  for (const char* scene : {"gated", "ungated"}) {
    fs::create_directories(root / scene);
    std::ofstream(root / scene / "summary.csv") << "# scene: " << scene << "\nlabel,status\na,ok\n";
  }
  std::ofstream(root / "gated" / "gates.toml")
      << "[[gate]]\nname = \"gated runs\"\nscene = \"gated\"\ncolumn = \"status\"\nequals = "
         "\"ok\"\n";
  const Outcome own = geomint("gate " + shell_quoted((root / "gated").string()));
  EXPECT_EQ(own.exit_code, 0) << own.output;
  EXPECT_NE(own.output.find("PASS gated runs (1 row(s))"), std::string::npos) << own.output;
  std::ofstream(root / "gates.toml") << "include = [\"*/gates.toml\"]\n";
  const Outcome both = geomint("gate " + shell_quoted((root / "gates.toml").string()) + " " +
                               shell_quoted((root / "gated").string()) + " " +
                               shell_quoted((root / "ungated").string()));
  EXPECT_EQ(both.exit_code, 0) << both.output;
  EXPECT_NE(both.output.find("scene 'ungated': it has no gates file"), std::string::npos)
      << both.output;
  EXPECT_EQ(both.output.find("scene 'gated':"), std::string::npos) << both.output;
  fs::remove_all(root);
}

// `geomint gate --format junit|json` (docs/CLI.md "gate"): the same verdicts and exit codes as the
// text format. Two scenes, a passing gate in one and a failing gate (with '<' and '"' in its name,
// which the writers must escape) in the other: the JUnit XML parses (xmllint --noout, Debian's
// libxml2-utils), has one <testsuite> per scene and one <testcase> per gate, and a <failure>
// exactly for the failing gate; the JSON is one object per gate.
TEST(Cli, GateFormatsJunitAndJsonCarryTheVerdictsAndTheExitCode) {
  const std::string root = GEOMINT_SOURCE_DIR;
  const std::string results = shell_quoted(root + "/results/fig1_pendulum/summary.csv") + " " +
                              shell_quoted(root + "/results/momentum/summary.csv");
  const fs::path gates = scratch("format_gates.toml");
  std::ofstream(gates) << "[[gate]]\nname = \"fig1 runs\"\nscene = \"fig1_pendulum\"\n"
                          "column = \"status\"\nequals = \"ok\"\n"
                          "[[gate]]\nname = \"too <strict> \\\"x\\\"\"\nscene = \"momentum\"\n"
                          "column = \"steps\"\nmax = 0\n";
  const Outcome text = geomint("gate " + shell_quoted(gates.string()) + " " + results);
  EXPECT_EQ(text.exit_code, 1) << text.output;
  EXPECT_NE(text.output.find("1 of 2 gate(s) passed"), std::string::npos) << text.output;

  const fs::path xml = scratch("gates.xml");
  const Outcome junit = geomint("gate --format junit " + shell_quoted(gates.string()) + " " +
                                results + " > " + shell_quoted(xml.string()));
  EXPECT_EQ(junit.exit_code, 1) << junit.output;
  std::ifstream in(xml);
  const std::string report((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto count = [&](const std::string& what) {
    int n = 0;
    for (auto at = report.find(what); at != std::string::npos; at = report.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("<testsuite "), 2) << report;
  EXPECT_EQ(count("<testcase "), 2) << report;
  EXPECT_EQ(count("<failure "), 1) << report;
  EXPECT_NE(report.find("<testsuite name=\"momentum\" tests=\"1\" failures=\"1\">"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("name=\"too &lt;strict&gt; &quot;x&quot;\""), std::string::npos) << report;
  if (std::system("command -v xmllint > /dev/null 2>&1") == 0) {
    const Outcome lint = geomint_shell("xmllint --noout " + shell_quoted(xml.string()));
    EXPECT_EQ(lint.exit_code, 0) << lint.output << report;
  } else {
    ADD_FAILURE() << "xmllint not found: install libxml2-utils (scripts/install-deps.sh)";
  }

  const Outcome json =
      geomint("gate --format json " + shell_quoted(gates.string()) + " " + results);
  EXPECT_EQ(json.exit_code, 1) << json.output;
  EXPECT_EQ(json.output.rfind("[\n  {\"scene\": \"fig1_pendulum\", \"gate\": \"fig1 runs\", "
                              "\"passed\": true, \"message\": \"",
                              0),
            0u)
      << json.output;
  EXPECT_NE(json.output.find("{\"scene\": \"momentum\", \"gate\": \"too <strict> \\\"x\\\"\", "
                             "\"passed\": false"),
            std::string::npos)
      << json.output;
  EXPECT_EQ(json.output.substr(json.output.size() - 4), "}\n]\n") << json.output;

  const fs::path passing = scratch("format_passing.toml");
  std::ofstream(passing) << "[[gate]]\nname = \"fig1 runs\"\ncolumn = \"status\"\nequals = "
                            "\"ok\"\n";
  for (const std::string format : {"text", "junit", "json"}) {
    EXPECT_EQ(geomint("gate --format " + format + " " + shell_quoted(passing.string()) + " " +
                      shell_quoted(root + "/results/fig1_pendulum/summary.csv"))
                  .exit_code,
              0)
        << format;
  }
  fs::remove(xml);
}

// gate --format junit|json stay valid whatever a gate name or a result path holds: a name with
// control characters (TOML \u escapes: BEL, ESC, form feed, DEL) and a result path with a byte
// that is not UTF-8 and one control character. The JUnit XML passes `xmllint --noout` (XML 1.0
// forbids U+0001–U+001F but tab, newline and return even as character references, so they show
// as \xNN) and the JSON reads back under Python's strict UTF-8 decoding and json parser.
TEST(Cli, GateFormatsStayValidForControlCharactersAndNonUtf8Paths) {
  const fs::path dir = scratch(std::string("odd\xff\x01path"));
  fs::create_directories(dir);
  fs::copy_file(std::string(GEOMINT_SOURCE_DIR) + "/results/momentum/summary.csv",
                dir / "summary.csv");
  const fs::path gates = scratch("control_gates.toml");
  std::ofstream(gates) << "[[gate]]\nname = \"bell\\u0007 esc\\u001b ff\\u000c del\\u007f "
                          "nul-free <&>\"\nscene = \"momentum\"\ncolumn = \"steps\"\nmax = 0\n";
  const std::string results = shell_quoted((dir / "summary.csv").string());
  const fs::path xml = scratch("control_gates.xml");
  const Outcome junit = geomint("gate --format junit --verbose " + shell_quoted(gates.string()) +
                                " " + results + " > " + shell_quoted(xml.string()));
  EXPECT_EQ(junit.exit_code, 1) << junit.output;
  const Outcome lint = geomint_shell("xmllint --noout " + shell_quoted(xml.string()));
  EXPECT_EQ(lint.exit_code, 0) << lint.output;
  std::ifstream in(xml);
  const std::string report((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(report.find("bell\\x07 esc\\x1B ff\\x0C"), std::string::npos) << report;
  EXPECT_NE(report.find("odd\xEF\xBF\xBD\\x01path"), std::string::npos) << report;

  const fs::path json = scratch("control_gates.json");
  const Outcome written = geomint("gate --format json --verbose " + shell_quoted(gates.string()) +
                                  " " + results + " > " + shell_quoted(json.string()));
  EXPECT_EQ(written.exit_code, 1) << written.output;
  const Outcome strict = geomint_shell(
      "/usr/bin/python3 -c \"import json, sys; text = open(sys.argv[1], 'rb').read()"
      ".decode('utf-8', 'strict'); rows = json.loads(text); "
      "assert rows[0]['gate'].startswith('bell\\x07 esc\\x1b ff\\x0c del\\x7f'), rows; "
      "assert 'odd\\ufffd\\x01path' in rows[0]['message'], rows; print('ok')\" " +
      shell_quoted(json.string()));
  EXPECT_EQ(strict.exit_code, 0) << strict.output;
  EXPECT_EQ(strict.output, "ok\n");
  fs::remove_all(dir);
  fs::remove(xml);
  fs::remove(json);
}

// perf-compare's CSV quotes fields per RFC 4180: templated benchmark names hold commas
// (`BM_X<a, b>`) and may hold quotes; every data row has the header's 9 fields under Python's csv
// reader and the names read back unchanged.
TEST(Cli, PerfCompareQuotesBenchmarkNamesWithCommasAndQuotes) {
  const auto document = [](double scale) {
    std::string rows;
    for (const std::string name : {"BM_X<a, b>", "BM_Y<\\\"q\\\", 2>", "BM_Plain"}) {
      for (int k = 0; k < 6; ++k) {
        rows += (rows.empty() ? "" : ",\n") + std::string("{\"name\": \"") + name +
                "\", \"run_type\": \"iteration\", \"iterations\": 10, \"real_time\": " +
                std::to_string(scale * (10 + 0.1 * k)) + ", \"time_unit\": \"us\"}";
      }
    }
    return "{\"context\": {\"commit\": \"abc\"}, \"benchmarks\": [\n" + rows + "\n]}\n";
  };
  const fs::path base = scratch("perf_base.json"), candidate = scratch("perf_new.json");
  std::ofstream(base) << document(1);
  std::ofstream(candidate) << document(1);
  const fs::path csv = scratch("perf.csv");
  const Outcome compared =
      geomint("perf-compare --quiet " + shell_quoted(base.string()) + " " +
              shell_quoted(candidate.string()) + " > " + shell_quoted(csv.string()));
  EXPECT_EQ(compared.exit_code, 0) << compared.output;
  const Outcome parsed = geomint_shell(
      "grep -v '^#' " + shell_quoted(csv.string()) +
      " | /usr/bin/python3 -c \"import csv, sys; rows = list(csv.reader(sys.stdin)); "
      "assert all(len(r) == 9 for r in rows), rows; print('|'.join(r[0] for r in rows))\"");
  EXPECT_EQ(parsed.exit_code, 0) << parsed.output;
  EXPECT_EQ(parsed.output, "benchmark|BM_Plain|BM_X<a, b>|BM_Y<\"q\", 2>\n");
  fs::remove(base);
  fs::remove(candidate);
  fs::remove(csv);
}

// gate --quiet (docs/CLI.md "Quiet and colour"): the text format prints the failing gates alone
// (nothing when all pass), exit codes unchanged; geomint prints no colour (no escape sequence),
// so NO_COLOR has nothing to turn off.
TEST(Cli, GateQuietPrintsOnlyFailuresAndNoColour) {
  const std::string results =
      shell_quoted(std::string(GEOMINT_SOURCE_DIR) + "/results/fig1_pendulum/summary.csv");
  const fs::path gates = scratch("quiet_gates.toml");
  std::ofstream(gates) << "[[gate]]\nname = \"fig1 runs\"\ncolumn = \"status\"\nequals = \"ok\"\n"
                          "[[gate]]\nname = \"too strict\"\ncolumn = \"steps\"\nmax = 0\n";
  const fs::path passing = scratch("quiet_passing.toml");
  std::ofstream(passing) << "[[gate]]\nname = \"fig1 runs\"\ncolumn = \"status\"\nequals = "
                            "\"ok\"\n";
  const Outcome loud = geomint("gate " + shell_quoted(gates.string()) + " " + results);
  EXPECT_EQ(loud.exit_code, 1) << loud.output;
  EXPECT_NE(loud.output.find("PASS fig1 runs"), std::string::npos) << loud.output;
  EXPECT_EQ(loud.output.find('\x1b'), std::string::npos) << loud.output;
  const Outcome quiet = geomint("gate --quiet " + shell_quoted(gates.string()) + " " + results);
  EXPECT_EQ(quiet.exit_code, 1) << quiet.output;
  EXPECT_NE(quiet.output.find("FAIL too strict"), std::string::npos) << quiet.output;
  EXPECT_EQ(quiet.output.find("PASS"), std::string::npos) << quiet.output;
  EXPECT_EQ(quiet.output.find("gate(s) passed"), std::string::npos) << quiet.output;
  const Outcome quiet_pass =
      geomint("gate --quiet " + shell_quoted(passing.string()) + " " + results);
  EXPECT_EQ(quiet_pass.exit_code, 0) << quiet_pass.output;
  EXPECT_EQ(quiet_pass.output, "");
  const Outcome quiet_bad =
      geomint("gate --quiet " + shell_quoted(passing.string()) + " /nonexistent.csv");
  EXPECT_EQ(quiet_bad.exit_code, 2) << quiet_bad.output;
  EXPECT_NE(quiet_bad.output.find("nonexistent.csv"), std::string::npos) << quiet_bad.output;
}

TEST(Readme, MethodAndProblemTablesMatchTheRegistry) {
  std::set<std::string> methods, problems;
  for (const auto& entry : integrator_registry()) methods.insert(entry.name);
  for (const auto& entry : problem_registry()) problems.insert(entry.name);
  EXPECT_EQ(readme_table_names("methods"), methods);
  EXPECT_EQ(readme_table_names("problems"), problems);
  const Outcome listing = geomint("list");
  for (const auto& name : methods) EXPECT_NE(listing.output.find(name), std::string::npos);
  for (const auto& name : problems) EXPECT_NE(listing.output.find(name), std::string::npos);
}

// `geomint list` prints aligned columns however long a name or capability list gets: in every
// row the third and fourth columns start where the header's do.
TEST(Cli, ListColumnsStayAlignedForTheLongestEntries) {
  for (const std::string what : {"methods", "problems"}) {
    const Outcome listing = geomint("list " + what);
    ASSERT_EQ(listing.exit_code, 0) << listing.output;
    std::istringstream lines(listing.output);
    std::string header;
    std::getline(lines, header);
    const std::size_t third = header.find(what == "methods" ? "flags" : "capabilities");
    const std::size_t fourth = header.find("parameters");
    ASSERT_NE(third, std::string::npos) << header;
    ASSERT_NE(fourth, std::string::npos) << header;
    std::string line;
    int rows = 0;
    while (std::getline(lines, line)) {
      if (line.empty()) continue;
      ++rows;
      ASSERT_GT(line.size(), third) << line;
      EXPECT_EQ(line[third - 1], ' ') << what << ": " << line;
      EXPECT_NE(line[third], ' ') << what << ": " << line;
      if (line.size() > fourth) {
        EXPECT_EQ(line[fourth - 1], ' ') << what << ": " << line;
        EXPECT_NE(line[fourth], ' ') << what << ": " << line;
      }
    }
    EXPECT_GT(rows, 10) << listing.output;
  }
}

// Values just outside each bound `geomint list NAME` prints for a parameter (Range, or the integer
// bounds), and just above the magnitude bound every real parameter has.
std::vector<std::string> values_just_outside(const ParamDoc& doc) {
  std::vector<std::string> out;
  const auto text = [](double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.17g", value);
    return std::string(buffer);
  };
  const double infinity = std::numeric_limits<double>::infinity();
  if (doc.kind == "integer" && doc.range) {
    if (doc.range->min > -1e15) out.push_back(std::to_string(std::lround(doc.range->min) - 1));
    if (doc.range->max < 1e15) out.push_back(std::to_string(std::lround(doc.range->max) + 1));
  }
  if (doc.kind == "real") {
    const Range range = doc.range.value_or(Range{});
    if (std::isfinite(range.min)) {
      out.push_back(text(range.min_open ? range.min : std::nextafter(range.min, -infinity)));
    }
    if (std::isfinite(range.max)) {
      out.push_back(text(range.max_open ? range.max : std::nextafter(range.max, infinity)));
    }
    if (range.nonzero) out.push_back("0");
    if (!(range.max < kMaxParameterMagnitude)) {
      out.push_back(text(std::nextafter(kMaxParameterMagnitude, infinity)));
    }
  }
  return out;
}

// `geomint list NAME` for every registered method and problem: its parameters with defaults and
// allowed ranges; and each printed range is the enforced one: a value just outside any bound is
// refused with exit 2 as out of range (rod_chain's n = 65 among them).
TEST(Cli, ListNameShowsEveryEntryAndEveryPrintedRangeIsEnforced) {
  const auto check = [](const std::string& name, const Params& params, bool method) -> int {
    const Outcome listing = geomint("list " + name);
    EXPECT_EQ(listing.exit_code, 0) << name << ":\n" << listing.output;
    if (listing.exit_code != 0) return 0;
    EXPECT_EQ(listing.output.rfind(name + (method ? " (method)" : " (problem)"), 0), 0)
        << listing.output;
    int refused = 0;
    for (const ParamDoc& doc : params.docs()) {
      EXPECT_NE(listing.output.find("\n" + doc.key + " "), std::string::npos)
          << name << ": no row for " << doc.key << ":\n"
          << listing.output;
      EXPECT_NE(listing.output.find(doc.allowed), std::string::npos) << name << " " << doc.key;
      for (const std::string& value : values_just_outside(doc)) {
        const std::string spec = name + ":" + doc.key + "=" + value;
        const Outcome run = geomint(method ? "run --problem pendulum --method '" + spec + "'"
                                           : "run --problem '" + spec + "' --method rk4");
        EXPECT_EQ(run.exit_code, 2) << spec << ":\n" << run.output;
        EXPECT_NE(run.output.find("parameter " + doc.key + "="), std::string::npos) << spec << ":\n"
                                                                                    << run.output;
        EXPECT_NE(run.output.find("out of range (allowed: "), std::string::npos) << spec << ":\n"
                                                                                 << run.output;
        ++refused;
      }
    }
    return refused;
  };
  int entries = 0, refused = 0;
  for (const auto& entry : integrator_registry()) {
    if (!entry.builtin) continue;
    Params params(Spec{entry.name, {}}, entry.name);
    entry.factory(params);
    refused += check(entry.name, params, true);
    ++entries;
  }
  for (const auto& entry : problem_registry()) {
    if (!entry.builtin) continue;
    Params params(Spec{entry.name, {}}, entry.name);
    entry.factory(params);
    refused += check(entry.name, params, false);
    ++entries;
  }
  EXPECT_GT(entries, 40);
  EXPECT_GT(refused, 100);
  const Outcome rod_chain = geomint("list rod_chain");
  EXPECT_NE(rod_chain.output.find("1..4096"), std::string::npos) << rod_chain.output;
}

// The lines strictly between <!-- MARKER:begin --> and <!-- MARKER:end --> of its catalogue.
std::string readme_block(const std::string& marker) {
  std::ifstream in(table_file(marker));
  std::string line, block;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line == "<!-- " + marker + ":end -->") break;
    if (inside) block += line + "\n";
    if (line == "<!-- " + marker + ":begin -->") inside = true;
  }
  return block;
}

// The README's method and problem tables are generated (docs/METHODS.md "Adding a method or a
// problem"): they must be `geomint list --markdown` verbatim, so a new or changed registry entry
// fails here with the rows to paste.
TEST(Readme, TablesAreTheOutputOfListMarkdown) {
  for (const std::string what : {"methods", "problems"}) {
    Outcome listing = geomint("list " + what + " --markdown");
    ASSERT_EQ(listing.exit_code, 0) << listing.output;
    const std::string readme = readme_block(what);
    if (readme == listing.output) continue;
    std::istringstream expected(listing.output), actual(readme);
    std::set<std::string> readme_rows;
    for (std::string row; std::getline(actual, row);) readme_rows.insert(row);
    std::string changed;
    for (std::string row; std::getline(expected, row);) {
      if (!readme_rows.count(row)) changed += "  " + row + "\n";
    }
    ADD_FAILURE() << table_file(what) << "'s " << what << " table is not `geomint list " << what
                  << " --markdown`. Run `make readme-tables`, or paste between <!-- " << what
                  << ":begin --> and <!-- " << what << ":end -->:\n"
                  << listing.output << "(rows new or changed:\n"
                  << changed << ")";
  }
}

// `geomint --help` documents every exit code main() returns (docs/USAGE.md "Exit codes").
TEST(Cli, HelpListsEveryExitCode) {
  const Outcome help = geomint("--help");
  EXPECT_EQ(help.exit_code, 0) << help.output;
  for (const char* code : {"0 ok", "1 a run failed", "2 bad input", "3 internal error"}) {
    EXPECT_NE(help.output.find(code), std::string::npos) << code << " missing in:\n" << help.output;
  }
}

// docs/CLUSTER.md "Running on a cluster": the CLI of sharded sweeps. Two shards of a scene's quick
// variant merge (exit 0) into <folder>/quick; without shard 1, merge exits 1 and names the
// resubmission; `geomint slurm` writes the three scripts next to the scene.
TEST(Cli, ShardMergeAndSlurmScripts) {
  const fs::path folder = scratch("cluster_scene");
  fs::create_directories(folder);
  std::ofstream(folder / "scene.toml")
      << "title = \"t\"\n[[runs]]\nlabel = \"a\"\nproblems = [\"harmonic\"]\n"
         "methods = [\"stormer_verlet\", \"rk4\", \"hp\"]\ndt = 0.1\nt_end = 1.0\n"
         "quick_t_end = 0.5\n";
  const std::string scene = (folder / "scene.toml").string();
  const fs::path out = folder / "quick";
  ASSERT_EQ(geomint("sweep " + shell_quoted(scene) + " --quick --shard 0/2").exit_code, 0);
  const Outcome refused = geomint("merge " + shell_quoted(out.string()));
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  EXPECT_NE(refused.output.find("shard 1/2: summary.1-of-2.csv is missing"), std::string::npos)
      << refused.output;
  EXPECT_NE(
      refused.output.find("sbatch --array=1 " + shell_quoted((folder / "sweep.sbatch").string())),
      std::string::npos)
      << refused.output;
  ASSERT_EQ(geomint("sweep " + shell_quoted(scene) + " --quick --shard 1/2").exit_code, 0);
  const Outcome merged = geomint("merge " + shell_quoted(out.string()));
  EXPECT_EQ(merged.exit_code, 0) << merged.output;
  std::ifstream summary(out / "summary.csv");
  const std::string text{std::istreambuf_iterator<char>(summary), {}};
  EXPECT_NE(text.find("# command: geomint sweep " + shell_quoted(scene) + " --quick --no-timing\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("# variant: quick\n"), std::string::npos) << text;
  const Outcome slurm =
      geomint("slurm " + shell_quoted(scene) + " --shards 2 --max-parallel 1 --time 0:10:00");
  EXPECT_EQ(slurm.exit_code, 0) << slurm.output;
  std::ifstream sweep(folder / "sweep.sbatch");
  const std::string script{std::istreambuf_iterator<char>(sweep), {}};
  for (const char* line : {"#SBATCH --array=0-1%1\n", "#SBATCH --requeue\n",
                           "#SBATCH --time=0:10:00\n", "--shard-from-env --shards 2 --no-timing"}) {
    EXPECT_NE(script.find(line), std::string::npos) << line << " in\n" << script;
  }
  EXPECT_TRUE(fs::exists(folder / "merge.sbatch"));
  std::ifstream timing(folder / "timing.sbatch");
  const std::string timing_script{std::istreambuf_iterator<char>(timing), {}};
  EXPECT_NE(timing_script.find("#SBATCH --exclusive"), std::string::npos) << timing_script;
  EXPECT_NE(timing_script.find("srun --cpu-bind=cores"), std::string::npos) << timing_script;
  fs::remove_all(folder);
}

// A sweep whose stderr is a pipe (a Slurm or CI log) prints heartbeat lines at the interval
// given by --progress-interval or GEOMINT_PROGRESS_INTERVAL (docs/CLI.md "sweep"), each with
// done/total runs and an ETA, and no carriage return; --quiet prints nothing but errors.
TEST(Cli, SweepInALogPrintsHeartbeatLines) {
  const fs::path folder = scratch("heartbeat_scene");
  fs::create_directories(folder);
  std::ofstream(folder / "scene.toml")
      << "title = \"t\"\n[[runs]]\nlabel = \"a\"\nproblems = [\"harmonic:omega=3\"]\n"
         "methods = [\"stormer_verlet\", \"symplectic_euler_a\"]\ndt = 2e-4\nt_end = 20.0\n"
         "timing_repeats = 0\n";
  const std::string scene = shell_quoted((folder / "scene.toml").string());
  const std::regex heartbeat(
      R"(\[sweep\] [0-2]/2 runs, [0-9]+% of expected steps, [0-9.]+ s elapsed, ETA [^\n]+\n)");
  for (const std::string& sweep :
       {shell_quoted(GEOMINT_BINARY) + " sweep --progress-interval 0.01 " + scene,
        "GEOMINT_PROGRESS_INTERVAL=0.01 " + shell_quoted(GEOMINT_BINARY) + " sweep " + scene}) {
    const Outcome logged = geomint_shell(sweep + " < /dev/null");
    EXPECT_EQ(logged.exit_code, 0) << logged.output;
    const auto lines =
        std::distance(std::sregex_iterator(logged.output.begin(), logged.output.end(), heartbeat),
                      std::sregex_iterator());
    EXPECT_GE(lines, 1) << sweep << ":\n" << logged.output;
    EXPECT_EQ(logged.output.find('\r'), std::string::npos) << logged.output;
  }
  // --quiet: no heartbeat, no closing line; bad input is still reported, with exit 2.
  const Outcome quiet = geomint("sweep --quiet --progress-interval 0.01 " + scene);
  EXPECT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output, "");
  const Outcome quiet_bad =
      geomint("sweep --quiet " + shell_quoted((folder / "nosuch.toml").string()));
  EXPECT_EQ(quiet_bad.exit_code, 2) << quiet_bad.output;
  EXPECT_NE(quiet_bad.output.find("nosuch.toml"), std::string::npos) << quiet_bad.output;
  const Outcome bad = geomint_shell("GEOMINT_PROGRESS_INTERVAL=soon " +
                                    shell_quoted(GEOMINT_BINARY) + " sweep " + scene);
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("$GEOMINT_PROGRESS_INTERVAL"), std::string::npos) << bad.output;
  fs::remove_all(folder);
}

// The arguments of the `#SBATCH` lines of a script, as sbatch reads them (src/sbatch/opt.c,
// _get_argument): quotes group, a backslash escapes the next character even inside quotes, a
// bare '#' starts a comment.
std::vector<std::string> sbatch_arguments(const std::string& script) {
  std::vector<std::string> arguments;
  std::istringstream lines(script);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("#SBATCH", 0) != 0) continue;
    size_t at = 7;
    while (at < line.size()) {
      while (at < line.size() && std::isspace(static_cast<unsigned char>(line[at]))) ++at;
      if (at == line.size()) break;
      std::string argument;
      char quote = 0;
      bool escape = false;
      for (; at < line.size() && (quote || !std::isspace(static_cast<unsigned char>(line[at])));
           ++at) {
        const char c = line[at];
        if (escape) {
          escape = false;
        } else if (c == '\\') {
          escape = true;
          continue;
        } else if (quote) {
          if (c == quote) {
            quote = 0;
            continue;
          }
        } else if (c == '"' || c == '\'') {
          quote = c;
          continue;
        } else if (c == '#') {
          at = line.size();
          break;
        }
        argument += c;
      }
      if (!argument.empty()) arguments.push_back(argument);
    }
  }
  return arguments;
}

// docs/CLUSTER.md "Running on a cluster": the scripts of `geomint slurm` run a scene whose folder
// name holds a space, a quote, a '%' or a command substitution. Each array task, the merge and the
// timing job are run with bash as Slurm would (srun a stand-in that runs its command), and must
// treat the name as a name: the tables appear, and `touch PWNED` never runs. The #SBATCH values,
// read as sbatch reads them, name the folder too.
TEST(Cli, SlurmScriptsKeepEveryPathOneWord) {
  const fs::path root = scratch("slurm_quoting");
  fs::create_directories(root / "bin");
  std::ofstream(root / "bin/srun") << "#!/bin/sh\nwhile [ \"${1#--}\" != \"$1\" ]; do shift; "
                                      "done\nexec \"$@\"\n";
  fs::permissions(root / "bin/srun", fs::perms::owner_all);
  for (const std::string& name :
       std::vector<std::string>{"my results", "x$(touch PWNED)", "it's 100%"}) {
    SCOPED_TRACE(name);
    const fs::path folder = root / name;
    fs::create_directories(folder);
    std::ofstream(folder / "scene.toml")
        << "title = \"t\"\n[[runs]]\nlabel = \"a\"\nproblems = [\"harmonic\"]\n"
           "methods = [\"stormer_verlet\", \"rk4\"]\ndt = 0.1\nt_end = 1.0\ntiming_repeats = 1\n";
    const std::string in_root = "cd " + shell_quoted(root.string()) + " && ";
    const Outcome slurm =
        geomint_shell(in_root + shell_quoted(GEOMINT_BINARY) + " slurm " +
                      shell_quoted(name + "/scene.toml") + " --shards 2 --partition 'short queue'");
    ASSERT_EQ(slurm.exit_code, 0) << slurm.output;
    for (const char* task : {"0", "1"}) {
      const Outcome shard = geomint_shell(in_root + "SLURM_ARRAY_TASK_ID=" + task + " bash " +
                                          shell_quoted(name + "/sweep.sbatch"));
      EXPECT_EQ(shard.exit_code, 0) << shard.output;
    }
    const std::string on_path = "PATH=" + shell_quoted((root / "bin").string()) + ":\"$PATH\" ";
    for (const char* job : {"/merge.sbatch", "/timing.sbatch"}) {
      const Outcome outcome = geomint_shell(in_root + on_path + "bash " + shell_quoted(name + job));
      EXPECT_EQ(outcome.exit_code, 0) << job << "\n" << outcome.output;
    }
    EXPECT_TRUE(fs::exists(folder / "summary.csv"));
    EXPECT_TRUE(fs::exists(folder / "table.md"));
    std::ifstream timing(folder / "summary.csv");
    const std::string summary{std::istreambuf_iterator<char>(timing), {}};
    EXPECT_NE(summary.find("wall_s"), std::string::npos) << summary;
    std::ifstream sweep(folder / "sweep.sbatch");
    const std::string script{std::istreambuf_iterator<char>(sweep), {}};
    const auto arguments = sbatch_arguments(script);
    std::string percent_doubled;
    // geomint writes the absolute path with symbolic links resolved (the scratch folder may
    // sit below one, as in a build reached through a link).
    for (char c : fs::weakly_canonical(folder / "slurm-logs").string()) {
      percent_doubled += c == '%' ? std::string("%%") : std::string(1, c);
    }
    for (const std::string& expected :
         {"--job-name=geomint-sweep-" + name, "--output=" + percent_doubled + "/sweep-%A_%a.out",
          std::string("--partition=short queue")}) {
      EXPECT_NE(std::find(arguments.begin(), arguments.end(), expected), arguments.end())
          << expected << " in\n"
          << script;
    }
  }
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    EXPECT_NE(entry.path().filename(), "PWNED") << entry.path();
  }
  EXPECT_FALSE(fs::exists("PWNED"));
  fs::remove_all(root);
}

// A newline in a folder name would end an #SBATCH line or turn the rest of a comment into code:
// refused before any script is written.
TEST(Cli, SlurmRefusesAFolderNameWithANewline) {
  const fs::path root = scratch("slurm_newline");
  const fs::path folder = root / "a\ntouch PWNED";
  fs::create_directories(folder);
  std::ofstream(folder / "scene.toml")
      << "title = \"t\"\n[[runs]]\nlabel = \"a\"\nproblems = [\"harmonic\"]\n"
         "methods = [\"rk4\"]\ndt = 0.1\nt_end = 1.0\n";
  const Outcome slurm = geomint("slurm " + shell_quoted((folder / "scene.toml").string()));
  EXPECT_EQ(slurm.exit_code, 2) << slurm.output;
  EXPECT_NE(slurm.output.find("control character"), std::string::npos) << slurm.output;
  EXPECT_EQ(std::distance(fs::directory_iterator(folder), fs::directory_iterator{}), 1)
      << "only scene.toml";
  fs::remove_all(root);
}

// --series and --out that name one file through a symbolic link are refused before the run, as
// the same spelling is (the bad-input registry has "./x.csv" and "sub/../x.csv"; it cannot make
// links): a link to the folder, and a link to an existing series file.
TEST(Cli, SeriesAndOutThroughASymbolicLinkAreOneFile) {
  const fs::path folder = scratch("same_file_link");
  fs::create_directories(folder);
  fs::create_directory_symlink(".", folder / "here");
  std::ofstream(folder / "s.csv") << "old\n";
  fs::create_symlink("s.csv", folder / "alias.csv");
  const std::string run =
      "cd " + shell_quoted(folder.string()) + " && " + shell_quoted(GEOMINT_BINARY) +
      " run --problem pendulum --method rk4 --dt 0.1 --t-end 1 --timing-repeats 0 ";
  for (const char* outputs :
       {"--series new.csv --out here/new.csv", "--series s.csv --out alias.csv"}) {
    const Outcome outcome = geomint_shell(run + outputs);
    EXPECT_EQ(outcome.exit_code, 2) << outputs << "\n" << outcome.output;
    EXPECT_NE(outcome.output.find("name the same file"), std::string::npos) << outcome.output;
  }
  EXPECT_FALSE(fs::exists(folder / "new.csv"));
  std::ifstream series(folder / "s.csv");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(series), {}), "old\n");
  fs::remove_all(folder);
}

}  // namespace
}  // namespace cli_test
}  // namespace geomint
