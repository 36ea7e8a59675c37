// GoogleTest adapter of geomint::verify (verify/verify.hpp, docs/VERIFY.md "Verify your own
// integrator"): GEOMINT_VERIFY_METHOD(Name, "spec") instantiates one test per check of
// verify::check_names() for a method spec; checks its flags do not call for are skipped, failures
// print the figures.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "verify/verify.hpp"

namespace geomint::verify {

// EXPECT a passed check (the message is describe(result)); GTEST_SKIP one that does not apply.
#define GEOMINT_VERIFY_EXPECT_PASSED(result_expression)                                \
  do {                                                                                 \
    const ::geomint::verify::CheckResult geomint_result = (result_expression);         \
    if (!geomint_result.applies) GTEST_SKIP() << geomint_result.detail;                \
    EXPECT_TRUE(geomint_result.passed) << ::geomint::verify::describe(geomint_result); \
  } while (0)

// Test names from check names (already identifiers).
inline std::string check_test_name(const testing::TestParamInfo<std::string>& info) {
  return info.param;
}

}  // namespace geomint::verify

// Defines the parameterised suite <Name>Verify with one test per check, e.g.
// MyVerlet/MyVerletVerify.Check/declared_order_pendulum. The method must be registered before
// the tests run (register_method in main, or a static MethodRegistrar).
#define GEOMINT_VERIFY_METHOD(Name, method_spec)                                         \
  class Name##Verify : public ::testing::TestWithParam<std::string> {};                  \
  TEST_P(Name##Verify, Check) {                                                          \
    GEOMINT_VERIFY_EXPECT_PASSED(::geomint::verify::run_check(method_spec, GetParam())); \
  }                                                                                      \
  INSTANTIATE_TEST_SUITE_P(Name, Name##Verify,                                           \
                           ::testing::ValuesIn(::geomint::verify::check_names()),        \
                           ::geomint::verify::check_test_name)
