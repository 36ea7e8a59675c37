// Runtime registration of methods and problems from outside the tree (integrators/integrator.hpp
// register_method, problems/problem.hpp register_problem; docs/VERIFY.md "Verify your own
// integrator"). Its own executable: registering changes the process-wide registries the other
// suites iterate.
#include <gtest/gtest.h>

#include <algorithm>

#include "integrators/integrator.hpp"

namespace geomint {
namespace {

std::unique_ptr<Integrator> make_renamed_verlet(Params& params) {
  (void)params;  // no parameters of its own
  return make_integrator("stormer_verlet");
}

std::unique_ptr<Problem> make_renamed_harmonic(Params& params) {
  const double omega = params.real("omega", 1.0, "angular frequency");
  return make_problem("harmonic:omega=" + format_number(omega));
}

// A static registrar runs before main: the function-local registry is in place by then.
const MethodRegistrar kRegistrar(
    {"registrar_verlet", "stormer_verlet under another name", &make_renamed_verlet, {}});

TEST(Registration, StaticRegistrarAddsAnExternalEntry) {
  const auto& registry = integrator_registry();
  const auto entry = std::find_if(registry.begin(), registry.end(),
                                  [](const auto& e) { return e.name == "registrar_verlet"; });
  ASSERT_NE(entry, registry.end());
  EXPECT_FALSE(entry->builtin);
  EXPECT_TRUE(registry.front().builtin);
  EXPECT_EQ(make_integrator("registrar_verlet")->spec(), "registrar_verlet");
  // A method registered at run time is the user's (MethodProvider), whatever it is called.
  EXPECT_EQ(entry->provider.kind, MethodProvider::Kind::kUser);
  EXPECT_EQ(make_integrator("registrar_verlet")->provider().label(), "user");
  EXPECT_EQ(registry.front().provider.label(), "geomint");
  const auto specs = integrator_test_specs();
  EXPECT_NE(std::find(specs.begin(), specs.end(), "registrar_verlet"), specs.end());
}

TEST(Registration, MethodsAndProblemsReachTheFactories) {
  register_method({"external_verlet", "test", &make_renamed_verlet, {}});
  // An entry that says it wraps a library keeps that provider.
  IntegratorEntry wrapped{"external_wrapped_verlet", "test", &make_renamed_verlet, {}};
  wrapped.provider = MethodProvider::library_named("SomeLib");
  register_method(wrapped);
  EXPECT_EQ(method_provider("external_wrapped_verlet").label(), "library:SomeLib");
  EXPECT_EQ(method_provider("external_verlet").label(), "user");
  register_problem({"external_harmonic", "test", &make_renamed_harmonic, {"omega=2"}});
  EXPECT_EQ(make_integrator("external_verlet")->info().order, 2);
  const auto problem = make_problem("external_harmonic:omega=3");
  EXPECT_EQ(problem->name(), "external_harmonic");
  EXPECT_EQ(problem->spec(), "external_harmonic:omega=3");
  const auto specs = problem_test_specs();
  EXPECT_NE(std::find(specs.begin(), specs.end(), "external_harmonic:omega=2"), specs.end());
  EXPECT_THROW(make_problem("external_harmonic:beta=1"), InputError);
}

TEST(Registration, ABuiltInNameIsRefused) {
  try {
    register_method({"stormer_verlet", "clash", &make_renamed_verlet, {}});
    FAIL() << "a built-in name was accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("already registered (built-in)"), std::string::npos)
        << error.what();
  }
  EXPECT_THROW(register_problem({"pendulum", "clash", &make_renamed_harmonic, {}}), InputError);
  register_method({"twice_verlet", "once", &make_renamed_verlet, {}});
  EXPECT_THROW(register_method({"twice_verlet", "twice", &make_renamed_verlet, {}}), InputError);
}

TEST(Registration, NamesMustBeSpecNames) {
  for (const char* name : {"", "a:b", "with space", "x=1"}) {
    EXPECT_THROW(register_method({name, "bad", &make_renamed_verlet, {}}), InputError) << name;
    EXPECT_THROW(register_problem({name, "bad", &make_renamed_harmonic, {}}), InputError) << name;
  }
  EXPECT_THROW(register_method({"no_factory", "bad", nullptr, {}}), InputError);
}

}  // namespace
}  // namespace geomint
