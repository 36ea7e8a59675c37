// `geomint reference`: a reference solution (Gauss s=3 in long double, checked against the 2*dt
// run; harness/reference_generator.hpp) for problems without an exact solution (docs/CLI.md
// "reference").
#include <fmt/format.h>

#include <memory>

#include "harness/cli/verbs.hpp"
#include "harness/reference_generator.hpp"
#include "problems/spec.hpp"

namespace geomint::cli {
namespace {

struct ReferenceCliOptions {
  std::string problem_spec, out_path;
  double t_end = 0, dt = 0, every = 0;
  bool every_given = false, dt_given = false;
};

int run_reference(const ReferenceCliOptions& cli, const Context& context) {
  if (cli.every_given && !(cli.every > 0)) {
    throw InputError(
        fmt::format("--every must be > 0 (got {}); leave it out for t-end/100", cli.every));
  }
  if (cli.dt_given && !(cli.dt > 0)) {
    throw InputError(
        fmt::format("--dt must be > 0 (got {}); leave it out for the default", cli.dt));
  }
  ReferenceOptions options;
  options.problem_spec = cli.problem_spec;
  options.t_end = cli.t_end;
  options.dt = cli.dt;
  options.output_every = cli.every;
  options.out_path = cli.out_path;
  options.command_line = context.command_line;
  const ReferenceSummary summary = generate_reference(options);
  fmt::print("{}\n", summary.path);
  inform(context, fmt::format("reference: dt={:.6g}, {} steps, estimated error final {:.3g}, max "
                              "{:.3g} (difference to the 2*dt run), {:.1f} s",
                              summary.dt, summary.steps, summary.estimated_error_final,
                              summary.estimated_error_max, summary.seconds));
  return kExitOk;
}

}  // namespace

Verb add_reference(CLI::App& app) {
  auto options = std::make_shared<ReferenceCliOptions>();
  auto* command = app.add_subcommand(
      "reference",
      "Write a reference solution (Gauss s=3 in long double, checked at 2*dt) to "
      "results/references/<problem>.csv");
  command->add_option("--problem", options->problem_spec, "problem spec")->required();
  command->add_option("--t-end", options->t_end, "horizon (> 0)")->required();
  command->add_option("--dt", options->dt, "step (default: the problem's default dt / 8)");
  command->add_option("--every", options->every,
                      "spacing of the written rows (> 0; default: t-end/100; must divide t-end)");
  command->add_option("--out", options->out_path, "output file (default: results/references/...)");
  return {"reference", command, [options, command](const Context& context) {
            ReferenceCliOptions given = *options;
            given.every_given = command->count("--every") > 0;
            given.dt_given = command->count("--dt") > 0;
            return run_reference(given, context);
          }};
}

}  // namespace geomint::cli
