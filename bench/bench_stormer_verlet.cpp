// Cost of the Integrator interface (docs/DESIGN.md §2): a Störmer–Verlet step (GNI §I.1.4) on
// Kepler and on a 128-dof spring net through Problem/Integrator, against hand-written loops doing
// the same kick–drift–kick arithmetic with one gradient per step (first same as last). Interface
// = Integrator::advance over a grid, the path of the harness's timing pass;
// StepCall = one virtual step() per step, the path of the metric pass. Prints the ratios.
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace {

using geomint::Vec;

constexpr double kStep = 1e-3;
constexpr int kStepsPerIteration = 1000;

// The harness's path: Integrator::advance over kStepsPerIteration grid steps, no visitor.
void run_interface(benchmark::State& state, const std::string& problem_spec) {
  const auto problem = geomint::make_problem(problem_spec);
  const auto integrator = geomint::make_integrator("stormer_verlet");
  geomint::State s = problem->initial_state();
  integrator->reset(*problem, s, kStep);
  for (auto _ : state) {
    const geomint::StepGrid grid{s.t, kStep, kStep * kStepsPerIteration, kStepsPerIteration};
    const geomint::AdvanceOutcome outcome =
        integrator->advance(*problem, s, grid, geomint::StepVisitor());
    if (!outcome.status.ok) state.SkipWithError(outcome.status.message.c_str());
    benchmark::DoNotOptimize(s.q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}

// One virtual Integrator::step per step, with its gradient cache check.
void run_step_calls(benchmark::State& state, const std::string& problem_spec) {
  const auto problem = geomint::make_problem(problem_spec);
  const auto integrator = geomint::make_integrator("stormer_verlet");
  geomint::State s = problem->initial_state();
  integrator->reset(*problem, s, kStep);
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      const geomint::StepStatus status = integrator->step(*problem, s, kStep);
      if (!status.ok) state.SkipWithError(status.message.c_str());
    }
    benchmark::DoNotOptimize(s.q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}

void BM_InterfaceKepler(benchmark::State& state) { run_interface(state, "kepler:e=0.6"); }
BENCHMARK(BM_InterfaceKepler);
void BM_StepCallKepler(benchmark::State& state) { run_step_calls(state, "kepler:e=0.6"); }
BENCHMARK(BM_StepCallKepler);

// Kepler by hand on scalars: V = −1/|q|, M = I, the same initial state as kepler:e=0.6.
void BM_HandLoopKepler(benchmark::State& state) {
  const double eccentricity = 0.6;
  double qx = 1 - eccentricity, qy = 0;
  double px = 0, py = std::sqrt((1 + eccentricity) / (1 - eccentricity));
  auto gradient = [](double x, double y, double& gx, double& gy) {
    const double r = std::sqrt(x * x + y * y);
    const double inv_r3 = 1 / (r * r * r);
    gx = x * inv_r3;
    gy = y * inv_r3;
  };
  double gx, gy;
  gradient(qx, qy, gx, gy);
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      px -= (kStep / 2) * gx;
      py -= (kStep / 2) * gy;
      qx += kStep * px;
      qy += kStep * py;
      gradient(qx, qy, gx, gy);
      px -= (kStep / 2) * gx;
      py -= (kStep / 2) * gy;
    }
    benchmark::DoNotOptimize(qx);
    benchmark::DoNotOptimize(py);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}
BENCHMARK(BM_HandLoopKepler);

// The same loop on the library's Vec and virtual Problem::gradient: separates the cost of the
// Problem interface (dynamic-size vectors, virtual call) from that of Integrator::step.
void BM_HandLoopKeplerProblemGradient(benchmark::State& state) {
  const auto problem = geomint::make_problem("kepler:e=0.6");
  geomint::State s = problem->initial_state();
  Vec g(s.q.size());
  problem->gradient(s.q, g);
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      s.p -= (kStep / 2) * g;
      s.q += kStep * s.p;
      problem->gradient(s.q, g);
      s.p -= (kStep / 2) * g;
    }
    benchmark::DoNotOptimize(s.q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}
BENCHMARK(BM_HandLoopKeplerProblemGradient);

// Larger state: the interface cost is per step, so it should vanish against a real gradient.
// The hand loop calls the same Problem::gradient, so only the stepping code differs.
void BM_InterfaceSpringNet(benchmark::State& state) { run_interface(state, "spring_net"); }
BENCHMARK(BM_InterfaceSpringNet);
void BM_StepCallSpringNet(benchmark::State& state) { run_step_calls(state, "spring_net"); }
BENCHMARK(BM_StepCallSpringNet);

void BM_HandLoopSpringNet(benchmark::State& state) {
  const auto problem = geomint::make_problem("spring_net");
  geomint::State s = problem->initial_state();
  const Vec inverse_mass = problem->inverse_mass();
  Vec g(s.q.size());
  problem->gradient(s.q, g);
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      s.p -= (kStep / 2) * g;
      s.q += kStep * inverse_mass.cwiseProduct(s.p);
      problem->gradient(s.q, g);
      s.p -= (kStep / 2) * g;
    }
    benchmark::DoNotOptimize(s.q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}
BENCHMARK(BM_HandLoopSpringNet);

// Console output plus each benchmark's CPU time (the median over --benchmark_repetitions when
// there are repetitions), for the ratios printed at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      const bool median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
      if (run.run_type == Run::RT_Iteration || median) {
        cpu_[run.run_name.function_name] = run.GetAdjustedCPUTime();
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
  void print_ratio(const std::string& numerator, const std::string& denominator) const {
    const auto a = cpu_.find(numerator), b = cpu_.find(denominator);
    if (a == cpu_.end() || b == cpu_.end()) return;
    std::printf("ratio %s / %s = %.3f\n", numerator.c_str(), denominator.c_str(),
                a->second / b->second);
  }

 private:
  std::map<std::string, double> cpu_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  for (const char* scene : {"Kepler", "SpringNet"}) {
    const std::string hand = std::string("BM_HandLoop") + scene;
    reporter.print_ratio(std::string("BM_Interface") + scene, hand);
    reporter.print_ratio(std::string("BM_StepCall") + scene, hand);
  }
  benchmark::Shutdown();
  return 0;
}
