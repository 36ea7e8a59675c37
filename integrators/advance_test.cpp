// Integrator::advance (docs/DESIGN.md §2): every fixed-step method's run over a
// grid, with or without a visitor, ends bit for bit where step() called once per grid step ends,
// with the same counters; the explicit methods' loops allocate nothing per step.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"

// Counts heap allocations so that a test can assert a loop makes none. Sanitizer builds keep
// their own allocator (the count is then not taken).
#if defined(__SANITIZE_ADDRESS__)
#define GEOMINT_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GEOMINT_COUNT_ALLOCATIONS 0
#endif
#endif
#ifndef GEOMINT_COUNT_ALLOCATIONS
#define GEOMINT_COUNT_ALLOCATIONS 1
#endif

#if GEOMINT_COUNT_ALLOCATIONS
namespace {
std::atomic<long> allocation_count{0};
}  // namespace
// glibc lets the executable interpose malloc; operator new and Eigen's dynamic vectors both
// allocate through it, so this counts every heap allocation of the loops under test.
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* malloc(std::size_t size) noexcept {
  allocation_count.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
#endif

namespace geomint {
namespace advance_test {
namespace {

// The harness's per-step path: step() on each grid step, t set to the grid time after it.
State step_by_step(Integrator& integrator, const Problem& problem, const StepGrid& grid) {
  State state = problem.initial_state();
  integrator.reset(problem, state, grid.dt);
  for (long k = 1; k <= grid.n; ++k) {
    const double t_next = grid.time(k);
    EXPECT_TRUE(integrator.step(problem, state, t_next - state.t).ok);
    state.t = t_next;
  }
  return state;
}

void expect_same_counters(const Counters& a, const Counters& b) {
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.force_evals, b.force_evals);
  EXPECT_EQ(a.energy_evals, b.energy_evals);
  EXPECT_EQ(a.hessian_evals, b.hessian_evals);
  EXPECT_EQ(a.newton_iters, b.newton_iters);
}

// A grid whose last step is shortened, so h varies from step to step as in real runs.
constexpr StepGrid kGrid{0.0, 0.01, 0.995, 100};

struct Case {
  std::string method;
  std::string problem;
};
// Printed into the ctest name ("  # GetParam() = ..."): without it GoogleTest prints the struct's
// bytes, pointers included, so the name changed from build to build.
void PrintTo(const Case& c, std::ostream* os) { *os << c.method << " on " << c.problem; }

class AdvanceMatchesStep : public ::testing::TestWithParam<Case> {};

TEST_P(AdvanceMatchesStep, BitForBitWithAndWithoutVisitor) {
  const auto problem = make_problem(GetParam().problem);
  const auto reference_method = make_integrator(GetParam().method);
  const State expected = step_by_step(*reference_method, *problem, kGrid);

  for (const bool with_visitor : {false, true}) {
    SCOPED_TRACE(with_visitor ? "with visitor" : "without visitor");
    const auto method = make_integrator(GetParam().method);
    State state = problem->initial_state();
    method->reset(*problem, state, kGrid.dt);
    long visits = 0;
    auto count_visits = [&](const State& seen, long k) {
      EXPECT_EQ(seen.t, kGrid.time(k));
      return ++visits > 0;
    };
    const AdvanceOutcome outcome = method->advance(
        *problem, state, kGrid, with_visitor ? StepVisitor(count_visits) : StepVisitor());
    EXPECT_TRUE(outcome.status.ok);
    EXPECT_EQ(outcome.steps, kGrid.n);
    EXPECT_EQ(visits, with_visitor ? kGrid.n : 0);
    EXPECT_EQ(state.t, expected.t);
    for (int i = 0; i < problem->dof(); ++i) {
      EXPECT_EQ(state.q[i], expected.q[i]) << "q_" << i;
      EXPECT_EQ(state.p[i], expected.p[i]) << "p_" << i;
    }
    expect_same_counters(method->counters(), reference_method->counters());
  }
}

// Kepler, Hénon–Heiles, harmonic and pendulum offer a fixed gradient (the statically typed loop),
// spring_net does not, damped_oscillator is forced; hp is an implicit method on the default path.
INSTANTIATE_TEST_SUITE_P(
    Methods, AdvanceMatchesStep,
    ::testing::Values(
        Case{"stormer_verlet", "kepler:e=0.6"}, Case{"stormer_verlet", "henon_heiles"},
        Case{"stormer_verlet", "harmonic"}, Case{"stormer_verlet", "pendulum:theta0=1.5"},
        Case{"stormer_verlet", "spring_net"}, Case{"stormer_verlet", "damped_oscillator"},
        Case{"symplectic_euler_a", "damped_oscillator"}, Case{"symplectic_euler_b", "kepler:e=0.6"},
        Case{"rk4", "kepler:e=0.6"}, Case{"rk4", "damped_oscillator"}, Case{"hp", "kepler:e=0.6"},
        Case{"position_verlet", "kepler:e=0.6"}, Case{"position_verlet", "damped_oscillator"},
        Case{"stormer_verlet:compensated=true", "kepler:e=0.6"},
        Case{"stormer_verlet:compensated=true", "damped_oscillator"}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string name = info.param.method + "_" + info.param.problem;
      for (char& c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      }
      return name;
    });

// A visitor that says stop ends the run after that step, with the steps before it counted.
TEST(Advance, VisitorStopsTheRun) {
  const auto problem = make_problem("kepler:e=0.6");
  const auto method = make_integrator("stormer_verlet");
  State state = problem->initial_state();
  method->reset(*problem, state, kGrid.dt);
  auto stop_at_seven = [](const State&, long k) { return k < 7; };
  const AdvanceOutcome outcome =
      method->advance(*problem, state, kGrid, StepVisitor(stop_at_seven));
  EXPECT_TRUE(outcome.status.ok);
  EXPECT_EQ(outcome.steps, 6);
  EXPECT_EQ(state.t, kGrid.time(7));
  EXPECT_EQ(method->counters().steps, 7);
}

#if GEOMINT_COUNT_ALLOCATIONS
// After a first run has sized every buffer, a second run of the explicit loops allocates nothing
// (no per-step allocation or string construction on the hot path).
TEST(Advance, ExplicitLoopsDoNotAllocate) {
  for (const char* method_spec :
       {"stormer_verlet", "position_verlet", "symplectic_euler_a", "symplectic_euler_b", "rk4"}) {
    for (const char* problem_spec : {"kepler:e=0.6", "spring_net", "damped_oscillator"}) {
      SCOPED_TRACE(std::string(method_spec) + " on " + problem_spec);
      const auto problem = make_problem(problem_spec);
      const auto method = make_integrator(method_spec);
      State state = problem->initial_state();
      method->reset(*problem, state, kGrid.dt);
      ASSERT_TRUE(method->advance(*problem, state, kGrid, StepVisitor()).status.ok);
      const StepGrid next{state.t, kGrid.dt, 1.0, 100};
      const long before = allocation_count.load();
      const AdvanceOutcome outcome = method->advance(*problem, state, next, StepVisitor());
      EXPECT_EQ(allocation_count.load() - before, 0);
      EXPECT_TRUE(outcome.status.ok) << outcome.status.message;
    }
  }
}
#endif

}  // namespace
}  // namespace advance_test
}  // namespace geomint
