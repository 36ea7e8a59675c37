// The engine adapters' own cost per step (docs/ENGINES.md "Adapter overhead"): on a 10-link joint
// chain, each engine's bare step against the geomint method's step (engine step + the state copy
// out: joint angles and rates back to absolute angles, p = M(θ)θ̇), and the copy out and in alone.
// Model building is outside every timed loop. Prints the overhead ratios.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engines/bullet.hpp"
#include "engines/dart.hpp"
#include "engines/mujoco.hpp"
#include "engines/ode.hpp"
#include "engines/planar_chain.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace {

using geomint::Vec;

constexpr double kStep = 1e-3;
constexpr int kStepsPerIteration = 100;
const char* const kChain = "rod_chain:coordinates=joint,n=10,theta=0.3";

geomint::engines::PlanarChain chain_of(const geomint::Problem& problem) {
  std::string why;
  const auto chain = geomint::engines::planar_chain_of(problem, why);
  if (!chain) throw std::logic_error(why);
  return *chain;
}

// The engine alone: its step, as the adapter calls it, from the problem's initial state.
template <class Engine, class Options>
void run_engine_step(benchmark::State& state, const Options& options) {
  const auto problem = geomint::make_problem(kChain);
  Engine engine(chain_of(*problem), options);
  const geomint::State initial = problem->initial_state();
  engine.set_state(initial.q, geomint::engines::chain_velocity(*problem, initial.q, initial.p));
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      const geomint::StepStatus status = engine.step(kStep);
      if (!status.ok) state.SkipWithError(status.message.c_str());
    }
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}

// The geomint method: Integrator::step, the path of every run (engine step + state copy out).
void run_method_step(benchmark::State& state, const std::string& spec) {
  const auto problem = geomint::make_problem(kChain);
  const auto method = geomint::make_integrator(spec);
  geomint::State s = problem->initial_state();
  method->reset(*problem, s, kStep);
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      const geomint::StepStatus status = method->step(*problem, s, kStep);
      if (!status.ok) state.SkipWithError(status.message.c_str());
    }
    benchmark::DoNotOptimize(s.q.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}

// The copy out alone, as ChainEngineMethod::step does it after the engine's step: the engine's
// state in absolute angles and rates, p = M(θ)θ̇ from the problem's mass, and the record of the
// state written (which spares the copy in on the next step).
// `problem_mass`: p through the problem's mass operator even where the adapter takes it from the
// engine's own mass matrix (MuJoCo's Euler and implicit steps): the copy out before that change,
// measured in the same run.
template <class Engine, class Options>
void run_copy_out(benchmark::State& state, const Options& options, bool problem_mass = false) {
  const auto problem = geomint::make_problem(kChain);
  Engine engine(chain_of(*problem), options);
  geomint::State s = problem->initial_state();
  engine.set_state(s.q, geomint::engines::chain_velocity(*problem, s.q, s.p));
  Vec velocity, written_q, written_p;
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      engine.get_state(s.q, velocity);
      bool engine_momentum = false;
      if constexpr (requires(Engine & e, Vec & p) { e.momentum_absolute(p); }) {
        if (!problem_mass) engine_momentum = engine.momentum_absolute(s.p);
      }
      if (!engine_momentum) s.p = geomint::engines::chain_momentum(*problem, s.q, velocity);
      written_q = s.q;
      written_p = s.p;
      benchmark::DoNotOptimize(written_p.data());
    }
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}

// The copy in: θ̇ = M(θ)⁻¹p and the engine's state from (θ, θ̇). A run pays it once (and again only
// when something else changed the state, e.g. a reversibility check), not per step.
template <class Engine, class Options>
void run_copy_in(benchmark::State& state, const Options& options) {
  const auto problem = geomint::make_problem(kChain);
  Engine engine(chain_of(*problem), options);
  const geomint::State s = problem->initial_state();
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      engine.set_state(s.q, geomint::engines::chain_velocity(*problem, s.q, s.p));
    }
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}

// The largest part of the copy out, engine-independent: p = M(θ)θ̇ through the problem's own
// mass matrix (O(n²) entries, each with a cosine, for the joint chain).
void BM_MomentumOnly(benchmark::State& state) {
  const auto problem = geomint::make_problem(kChain);
  const geomint::State s = problem->initial_state();
  const Vec velocity = geomint::engines::chain_velocity(*problem, s.q, s.p);
  for (auto _ : state) {
    for (int k = 0; k < kStepsPerIteration; ++k) {
      Vec p = geomint::engines::chain_momentum(*problem, s.q, velocity);
      benchmark::DoNotOptimize(p.data());
    }
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * kStepsPerIteration);
}
BENCHMARK(BM_MomentumOnly);

using geomint::engines::BulletChain;
using geomint::engines::BulletOptions;
using geomint::engines::DartChain;
using geomint::engines::DartOptions;
using geomint::engines::MujocoChain;
using geomint::engines::MujocoOptions;
using geomint::engines::OdeChain;
using geomint::engines::OdeOptions;

void BM_EngineStep_mujoco(benchmark::State& state) {
  run_engine_step<MujocoChain>(state, MujocoOptions{"euler", false});
}
void BM_MethodStep_mujoco(benchmark::State& state) { run_method_step(state, "mujoco"); }
void BM_CopyOut_mujoco(benchmark::State& state) {
  run_copy_out<MujocoChain>(state, MujocoOptions{"euler", false});
}
void BM_CopyOutProblemMass_mujoco(benchmark::State& state) {
  run_copy_out<MujocoChain>(state, MujocoOptions{"euler", false}, true);
}
void BM_CopyIn_mujoco(benchmark::State& state) {
  run_copy_in<MujocoChain>(state, MujocoOptions{"euler", false});
}
void BM_EngineStep_ode(benchmark::State& state) {
  run_engine_step<OdeChain>(state, OdeOptions{"world", false});
}
void BM_MethodStep_ode(benchmark::State& state) { run_method_step(state, "ode"); }
void BM_CopyOut_ode(benchmark::State& state) {
  run_copy_out<OdeChain>(state, OdeOptions{"world", false});
}
void BM_CopyIn_ode(benchmark::State& state) {
  run_copy_in<OdeChain>(state, OdeOptions{"world", false});
}
void BM_EngineStep_bullet(benchmark::State& state) {
  run_engine_step<BulletChain>(state, BulletOptions{"euler", false});
}
void BM_MethodStep_bullet(benchmark::State& state) { run_method_step(state, "bullet"); }
void BM_CopyOut_bullet(benchmark::State& state) {
  run_copy_out<BulletChain>(state, BulletOptions{"euler", false});
}
void BM_CopyIn_bullet(benchmark::State& state) {
  run_copy_in<BulletChain>(state, BulletOptions{"euler", false});
}
void BM_EngineStep_dart(benchmark::State& state) {
  run_engine_step<DartChain>(state, DartOptions{"world", false});
}
void BM_MethodStep_dart(benchmark::State& state) { run_method_step(state, "dart"); }
void BM_CopyOut_dart(benchmark::State& state) {
  run_copy_out<DartChain>(state, DartOptions{"world", false});
}
void BM_CopyIn_dart(benchmark::State& state) {
  run_copy_in<DartChain>(state, DartOptions{"world", false});
}
BENCHMARK(BM_EngineStep_mujoco);
BENCHMARK(BM_MethodStep_mujoco);
BENCHMARK(BM_CopyOut_mujoco);
BENCHMARK(BM_CopyOutProblemMass_mujoco);
BENCHMARK(BM_CopyIn_mujoco);
BENCHMARK(BM_EngineStep_ode);
BENCHMARK(BM_MethodStep_ode);
BENCHMARK(BM_CopyOut_ode);
BENCHMARK(BM_CopyIn_ode);
BENCHMARK(BM_EngineStep_bullet);
BENCHMARK(BM_MethodStep_bullet);
BENCHMARK(BM_CopyOut_bullet);
BENCHMARK(BM_CopyIn_bullet);
BENCHMARK(BM_EngineStep_dart);
BENCHMARK(BM_MethodStep_dart);
BENCHMARK(BM_CopyOut_dart);
BENCHMARK(BM_CopyIn_dart);

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
  // The adapter's share of a step, two ways: the copy out measured alone, and the method's step
  // less the engine's (the copy out plus the state comparison and the virtual call).
  void print_overhead(const std::string& engine) const {
    const auto step = cpu_.find("BM_EngineStep_" + engine);
    const auto method = cpu_.find("BM_MethodStep_" + engine);
    const auto copy_out = cpu_.find("BM_CopyOut_" + engine);
    const auto copy_in = cpu_.find("BM_CopyIn_" + engine);
    const auto copy_out_before = cpu_.find("BM_CopyOutProblemMass_" + engine);
    const auto momentum = cpu_.find("BM_MomentumOnly");
    if (step == cpu_.end()) return;
    if (copy_out != cpu_.end()) {
      std::printf("overhead %s: copy out / engine step = %.3f\n", engine.c_str(),
                  copy_out->second / step->second);
    }
    if (copy_out_before != cpu_.end()) {
      std::printf(
          "overhead %s: copy out through the problem's mass (before) / engine step = %.3f\n",
          engine.c_str(), copy_out_before->second / step->second);
    }
    if (momentum != cpu_.end()) {
      std::printf("overhead %s: of which p = M(q) v / engine step = %.3f\n", engine.c_str(),
                  momentum->second / step->second);
    }
    if (method != cpu_.end()) {
      std::printf("overhead %s: (method step - engine step) / engine step = %.3f\n", engine.c_str(),
                  (method->second - step->second) / step->second);
    }
    if (copy_in != cpu_.end()) {
      std::printf("overhead %s: copy in (once per run) / engine step = %.3f\n", engine.c_str(),
                  copy_in->second / step->second);
    }
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
  for (const char* engine : {"mujoco", "ode", "bullet", "dart"}) reporter.print_overhead(engine);
  benchmark::Shutdown();
  return 0;
}
