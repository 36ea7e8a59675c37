// The planar hinge chain that `pendulum`, `double_pendulum` and `rod_chain:coordinates=joint` are
// (point masses on massless rods from a fixed pivot, gravity down), read from the problem's own
// spec, and the maps between the problem's state (absolute angles θ, p) and an engine's joints.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint::engines {

struct PlanarChain {
  std::vector<double> mass;    // point mass at the end of rod i
  std::vector<double> length;  // rod i, from node i − 1 (the pivot for i = 0) to node i
  double gravity = 0;          // acceleration along the downward vertical
  int links() const { return static_cast<int>(mass.size()); }
};

// The problems a chain engine runs, for refusals and docs ("pendulum, double_pendulum, ...").
const std::vector<std::string>& chain_problem_specs();

// The chain `problem` is, from its canonical spec (every parameter written out, so nothing here
// repeats a default), or nullopt with `why` saying why it is none.
std::optional<PlanarChain> planar_chain_of(const Problem& problem, std::string& why);

// Joint angles of an engine chain are relative (φ₁ = θ₁, φᵢ = θᵢ − θᵢ₋₁); the problem's are
// absolute from the downward vertical (θᵢ = φ₁ + … + φᵢ). The same maps hold for rates.
void absolute_to_relative(const Vec& absolute, Vec& relative);
void relative_to_absolute(const Vec& relative, Vec& absolute);

// θ̇ = M(θ)⁻¹p and p = M(θ)θ̇ through the problem's own mass: its LagrangianSystem where it is
// one (M(θ)), its constant diagonal mass otherwise (the pendulum).
Vec chain_velocity(const Problem& problem, const Vec& q, const Vec& p);
Vec chain_momentum(const Problem& problem, const Vec& q, const Vec& v);

// "" when `problem` is a planar chain, else why `method` (which `builds`, e.g. "builds a MuJoCo
// model of planar hinge chains only") refuses it, with the problems that apply.
std::string chain_refusal(const Problem& problem, const std::string& method,
                          const std::string& builds);

// The Integrator side every chain engine shares. The problem's state goes into the engine only
// when it is not the state the previous step wrote (a fresh run, a reversibility check), so a
// run follows the engine's own trajectory without a round trip through p = M(θ)θ̇ per step.
// Engine: constructed from (const PlanarChain&, const Options&), with set_state(θ, θ̇),
// StepStatus step(h) and get_state(θ, θ̇) in the problem's absolute angles.
template <class Engine, class Options>
class ChainEngineMethod : public Integrator, public RunsListedProblems {
 public:
  ChainEngineMethod(Options options, std::string builds)
      : options_(std::move(options)), builds_(std::move(builds)) {}

  std::string problem_refusal(const Problem& problem) const override {
    return chain_refusal(problem, info().name, builds_);
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    std::string why;
    const auto chain = planar_chain_of(problem, why);
    if (!chain) throw std::logic_error(problem_refusal(problem));
    engine_ = std::make_unique<Engine>(*chain, options_);
    written_q_.resize(0);
    written_p_.resize(0);
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (!engine_) reset(problem, state, h);
    // (Eigen compares vectors of equal size only; after reset() nothing has been written.)
    const bool engine_holds_state = written_q_.size() == state.q.size() &&
                                    written_p_.size() == state.p.size() && state.q == written_q_ &&
                                    state.p == written_p_;
    if (!engine_holds_state) {
      engine_->set_state(state.q, chain_velocity(problem, state.q, state.p));
    }
    const StepStatus status = engine_->step(h);
    ++counters_.steps;
    if (!status.ok) return status;
    engine_->get_state(state.q, velocity_);
    state.p = chain_momentum(problem, state.q, velocity_);
    state.t += h;
    written_q_ = state.q;
    written_p_ = state.p;
    return status;
  }

 protected:
  Options options_;

 private:
  std::string builds_;
  std::unique_ptr<Engine> engine_;
  Vec written_q_, written_p_, velocity_;
};

}  // namespace geomint::engines
