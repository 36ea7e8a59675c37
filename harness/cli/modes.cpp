// `geomint modes`: the normal modes of a method's one-step map on a linear problem, ω against
// the discrete ω̃ = θ/h and the amplitude ρ (harness/structure_metrics.hpp; docs/CLI.md "modes").
#include <fmt/format.h>

#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/run_spec.hpp"
#include "harness/structure_metrics.hpp"
#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint::cli {
namespace {

struct ModesOptions {
  std::string problem_spec, method_spec;
  double dt = 0;
};

int run_modes(const ModesOptions& options, const Context& context) {
  if (!(options.dt > 0)) throw InputError(fmt::format("--dt must be > 0 (got {})", options.dt));
  const auto problem = parse_problem(options.problem_spec);
  const MethodFactory method(options.method_spec);
  const Applicability can_run = applicable(method.prototype(), *problem);
  if (!can_run.ok) throw InputError(can_run.reason);
  const std::string why_not = normal_modes_not_applicable(method.prototype(), *problem);
  if (!why_not.empty()) {
    throw InputError(fmt::format("modes: {} on {}: {}", method.spec(), problem->spec(), why_not));
  }
  const std::vector<DiscreteMode> table = discrete_normal_modes(method, *problem, options.dt);
  if (table.empty()) {
    fmt::print(stderr, "{}: modes: the step failed\n", context.program);
    return kExitFailed;
  }
  // ω, the discrete ω̃ = θ/h, (ω̃ − ω)/ω (empty for a rigid mode) and ρ, one row per mode.
  fmt::print("mode,omega,omega_discrete,freq_err_rel,rho\n");
  for (size_t j = 0; j < table.size(); ++j) {
    const DiscreteMode& mode = table[j];
    const bool rigid = mode.omega <= 1e-8 * table.back().omega;
    fmt::print("{},{:.17g},{:.17g},{},{:.17g}\n", j + 1, mode.omega, mode.omega_discrete,
               rigid ? "" : fmt::format("{:.17g}", (mode.omega_discrete - mode.omega) / mode.omega),
               mode.amplitude);
  }
  return kExitOk;
}

}  // namespace

Verb add_modes(CLI::App& app) {
  auto options = std::make_shared<ModesOptions>();
  auto* command =
      app.add_subcommand("modes",
                         "Print the normal modes of a method's one-step map on a linear problem "
                         "(docs/USAGE.md \"Optional structure metrics\")");
  command->add_option("--problem", options->problem_spec, "linear problem spec")->required();
  command->add_option("--method", options->method_spec, "method spec")->required();
  command->add_option("--dt", options->dt, "step (> 0)")->required();
  return {"modes", command,
          [options](const Context& context) { return run_modes(*options, context); }};
}

}  // namespace geomint::cli
