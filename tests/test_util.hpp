// Shared GoogleTest helpers for every suite (docs/DESIGN.md §7, "Tests"). Bad input must be an
// InputError whose message names the offending input (docs/USAGE.md "Exit codes": exit 2 with a
// message naming the option, key or value), checked here once instead of in a copy per test file.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <utility>
#include <vector>

#include "problems/parallel.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace geomint::test {

// A .npy file (NumPy format 1.0) with the header dict `dict` (e.g. "{'descr': '<f8', ...}") and
// the float64 `values` as raw bytes: the header padded with spaces so the data starts at a
// multiple of 64 bytes, as numpy.save writes it.
inline std::string npy_file(const std::string& dict, const std::vector<double>& values) {
  std::string header = dict;
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes += static_cast<char>(header.size() & 0xff);
  bytes += static_cast<char>(header.size() >> 8);
  bytes += header;
  bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
  return bytes;
}

// Success when make(input) throws InputError and its message contains every fragment; the
// failure names the input and quotes the message, or says the input was accepted. Use as
// EXPECT_TRUE(input_error_names(make_problem, "kepler:e=1", "e=1")) so a failure points at the
// caller's line.
template <class Make>
::testing::AssertionResult input_error_names(Make&& make, const std::string& input,
                                             const std::vector<std::string>& fragments) {
  try {
    make(input);
  } catch (const InputError& error) {
    const std::string message = error.what();
    for (const auto& fragment : fragments) {
      if (message.find(fragment) == std::string::npos) {
        return ::testing::AssertionFailure()
               << input << ": the message does not name '" << fragment << "': " << message;
      }
    }
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << input << " was accepted";
}

template <class Make>
::testing::AssertionResult input_error_names(Make&& make, const std::string& input,
                                             const std::string& fragment) {
  return input_error_names(make, input, std::vector<std::string>{fragment});
}

// Pairs of a bad input and the fragment its message must contain.
using InputErrorCases = std::vector<std::pair<std::string, std::string>>;

// input_error_names for every case; the failure lists every case that failed.
template <class Make>
::testing::AssertionResult input_errors_name(Make&& make, const InputErrorCases& cases) {
  std::string failures;
  for (const auto& [input, fragment] : cases) {
    const ::testing::AssertionResult result = input_error_names(make, input, fragment);
    if (!result) failures += std::string("\n  ") + result.message();
  }
  if (failures.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "bad input not rejected as expected:" << failures;
}

// Reproducible test vector with entries uniform in [-1, 1] (derivative and symmetry checks).
inline Vec random_vector(int n, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Vec v(n);
  for (int k = 0; k < n; ++k) v[k] = uniform(generator);
  return v;
}

// Restores the thread count (problems/parallel.hpp) the process had when a test ends.
class ThreadCountGuard {
 public:
  ThreadCountGuard() : saved_(thread_count()) {}
  ~ThreadCountGuard() { set_thread_count(saved_); }
  ThreadCountGuard(const ThreadCountGuard&) = delete;
  ThreadCountGuard& operator=(const ThreadCountGuard&) = delete;

 private:
  int saved_;
};

}  // namespace geomint::test
