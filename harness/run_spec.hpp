// A run's inputs as validated objects: the problem, a factory of fresh integrators and
// the RunConfig (time grid and outputs). Spec strings are parsed once, at the command line or the
// scene reader; RunSpec::validate() lists every error at once, as Ceres' Solver::Options::IsValid.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "harness/run.hpp"
#include "integrators/integrator.hpp"

namespace geomint {

// One method, parsed and checked once: make() returns a fresh integrator (reset, counters at 0)
// without re-parsing text; spec is the canonical spec the rows name.
class MethodFactory {
 public:
  // InputError for an unknown method, key or value (the registry's message).
  explicit MethodFactory(const std::string& spec_text);

  std::unique_ptr<Integrator> make() const { return maker_(); }
  const std::string& spec() const { return prototype_->spec(); }
  const MethodInfo& info() const { return info_; }
  bool adaptive() const { return (info_.flags & kAdaptive) != 0; }
  // An integrator that never runs, for questions about the method (applicable(), predictions).
  const Integrator& prototype() const { return *prototype_; }

 private:
  IntegratorMaker maker_;
  std::shared_ptr<const Integrator> prototype_;
  MethodInfo info_;
};

// The problem object a spec names (InputError for an unknown problem, key or value). Shared: runs
// of one problem (the levels of an order study, the repeats of a timing pass) read one object.
std::shared_ptr<const Problem> parse_problem(const std::string& spec_text);

// The objects of the spec texts a scene names, each text parsed once: the scene reader fills it
// while it checks the scene, and the sweep's runs, order studies, stability searches and
// table.md's short labels read the same objects (a problem is shared read-only, a method is a
// factory of fresh integrators). Safe to use from the sweep's worker threads.
class SpecBook {
 public:
  // The problem or method of `text`, parsed on first use (InputError as parse_problem and
  // MethodFactory throw it; a text that fails is not kept, so asking again gives the same error).
  std::shared_ptr<const Problem> problem(const std::string& text);
  const MethodFactory& method(const std::string& text);

 private:
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const Problem>> problems_;
  std::map<std::string, MethodFactory> methods_;  // std::map: references stay valid
};

struct RunSpec {
  std::shared_ptr<const Problem> problem;
  MethodFactory method;
  RunConfig config;  // time grid (dt, t_end, max_steps), outputs, timing, divergence rule

  // Parses both specs (InputError at the first unknown name, key or value: nothing to validate
  // without the objects). Does not validate.
  static RunSpec parse(const std::string& problem_spec, const std::string& method_spec,
                       const RunConfig& config);

  // Every error of this run's inputs, each naming the option (or key) and what is allowed: the
  // grid and counts (run_config_errors), the output paths, whether the method applies to the
  // problem, the Poincaré section. Empty when the run may start.
  std::vector<std::string> validate() const;
};

// One InputError carrying every message of `errors` (joined by "; "); nothing when empty.
void throw_input_errors(const std::vector<std::string>& errors);

}  // namespace geomint
