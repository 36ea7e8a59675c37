// The Integrator side every engine method shares: which problems it models (planar chains,
// engines/planar_chain.hpp, and one rigid body about a fixed point, engines/rotor.hpp), the
// engine model it builds for each, and the state's trip into the engine and back.
#pragma once

#include <concepts>
#include <memory>
#include <stdexcept>
#include <string>

#include "engines/planar_chain.hpp"
#include "engines/rotor.hpp"
#include "integrators/integrator.hpp"

namespace geomint::engines {

// An engine's model of a planar chain (engines/planar_chain.hpp), built from the problem's own
// parameters: set_state(θ, θ̇) and get_state(θ, θ̇) in the problem's absolute angles, one engine
// step of length h (a failure is a status naming the engine's message), and the engine's own
// potential and kinetic energy at the state last set, which the fidelity tests set against the
// problem's. Optional: bool momentum_absolute(Vec& p), p = M(θ)θ̇ from the engine's own mass
// matrix where it holds one at the new state (false: the caller uses the problem's).
template <class Engine, class Options>
concept ChainEngineModel = std::constructible_from<Engine, const PlanarChain&, const Options&> &&
    requires(Engine& engine, const Vec& in, Vec& out, double h) {
  engine.set_state(in, in);
  engine.get_state(out, out);
  { engine.step(h) } -> std::same_as<StepStatus>;
  { engine.potential() } -> std::convertible_to<double>;
  { engine.kinetic() } -> std::convertible_to<double>;
};

// An engine's model of one rigid body about a fixed point (engines/rotor.hpp): its state is the
// attitude and body angular velocity of the rotor's principal frame (RotorStateMap::to_principal);
// step and energies as ChainEngineModel.
template <class Engine, class Options>
concept RotorEngineModel = std::constructible_from<Engine, const Rotor&, const Options&> &&
    requires(Engine& engine, const RotorState& state, double h) {
  engine.set_state(state);
  { engine.get_state() } -> std::same_as<RotorState>;
  { engine.step(h) } -> std::same_as<StepStatus>;
  { engine.potential() } -> std::convertible_to<double>;
  { engine.kinetic() } -> std::convertible_to<double>;
};

// The problem's state goes into the engine only when it is not the state the previous step wrote
// (a fresh run, a reversibility check), so a run follows the engine's own trajectory without a
// round trip through the problem's momenta per step.
template <class ChainEngine, class RotorEngine, class Options>
requires ChainEngineModel<ChainEngine, Options> && RotorEngineModel<RotorEngine, Options>
class EngineMethod : public Integrator, public RunsListedProblems {
 public:
  EngineMethod(Options options, std::string engine)
      : options_(std::move(options)), engine_name_(std::move(engine)) {}

  std::string problem_refusal(const Problem& problem) const override {
    std::string why = engine_refusal(problem, info().name, engine_name_);
    return why.empty() ? option_refusal(problem) : why;
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    if (std::string why = problem_refusal(problem); !why.empty()) throw std::logic_error(why);
    chain_engine_.reset();
    rotor_engine_.reset();
    rotor_map_.reset();
    std::string ignored;
    if (const auto chain = planar_chain_of(problem, ignored)) {
      chain_engine_ = std::make_unique<ChainEngine>(*chain, options_);
    } else {
      const auto rotor = rotor_of(problem, ignored);
      rotor_engine_ = std::make_unique<RotorEngine>(*rotor, options_);
      rotor_map_ = std::make_unique<RotorStateMap>(*rotor);
    }
    written_q_.resize(0);
    written_p_.resize(0);
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (!chain_engine_ && !rotor_engine_) reset(problem, state, h);
    // (Eigen compares vectors of equal size only; after reset() nothing has been written.)
    const bool engine_holds_state = written_q_.size() == state.q.size() &&
                                    written_p_.size() == state.p.size() && state.q == written_q_ &&
                                    state.p == written_p_;
    StepStatus status;
    if (chain_engine_) {
      if (!engine_holds_state) {
        chain_engine_->set_state(state.q, chain_velocity(problem, state.q, state.p));
      }
      status = chain_engine_->step(h);
      ++counters_.steps;
      if (!status.ok) return status;
      chain_engine_->get_state(state.q, velocity_);
      // An engine that holds its mass matrix at the new state gives p from it (the fidelity
      // tests show it equals the problem's); the others go through the problem's mass operator.
      bool engine_momentum = false;
      if constexpr (requires(ChainEngine & engine, Vec & p) { engine.momentum_absolute(p); }) {
        engine_momentum = chain_engine_->momentum_absolute(state.p);
      }
      if (!engine_momentum) state.p = chain_momentum(problem, state.q, velocity_);
    } else {
      if (!engine_holds_state) {
        rotor_engine_->set_state(rotor_map_->to_principal(rotor_map_->to_rotor(problem, state)));
      }
      status = rotor_engine_->step(h);
      ++counters_.steps;
      if (!status.ok) return status;
      rotor_map_->to_problem(problem, rotor_map_->from_principal(rotor_engine_->get_state()),
                             state);
    }
    state.t += h;
    written_q_ = state.q;
    written_p_ = state.p;
    return status;
  }

 protected:
  // An option the engine has only for some of its problems (Bullet's gyro= for its btRigidBody)
  // refuses the others: "" when it applies.
  virtual std::string option_refusal(const Problem&) const { return ""; }
  Options options_;

 private:
  std::string engine_name_;
  std::unique_ptr<ChainEngine> chain_engine_;
  std::unique_ptr<RotorEngine> rotor_engine_;
  std::unique_ptr<RotorStateMap> rotor_map_;
  Vec written_q_, written_p_, velocity_;
};

}  // namespace geomint::engines
