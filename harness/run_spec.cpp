// RunSpec (see run_spec.hpp): the one place outside the command line and the scene reader where
// problem and method specs become objects.
#include "harness/run_spec.hpp"

#include <fmt/format.h>

#include "harness/paths.hpp"
#include "harness/structure_metrics.hpp"

namespace geomint {

MethodFactory::MethodFactory(const std::string& spec_text)
    : maker_(integrator_maker(spec_text)), prototype_(maker_()), info_(prototype_->info()) {}

std::shared_ptr<const Problem> parse_problem(const std::string& spec_text) {
  return make_problem(spec_text);
}

std::shared_ptr<const Problem> SpecBook::problem(const std::string& text) {
  const std::lock_guard<std::mutex> lock(mutex_);
  auto found = problems_.find(text);
  if (found == problems_.end()) found = problems_.emplace(text, parse_problem(text)).first;
  return found->second;
}

const MethodFactory& SpecBook::method(const std::string& text) {
  const std::lock_guard<std::mutex> lock(mutex_);
  auto found = methods_.find(text);
  if (found == methods_.end()) found = methods_.emplace(text, MethodFactory(text)).first;
  return found->second;
}

RunSpec RunSpec::parse(const std::string& problem_spec, const std::string& method_spec,
                       const RunConfig& config) {
  auto problem = parse_problem(problem_spec);
  return RunSpec{std::move(problem), MethodFactory(method_spec), config};
}

std::vector<std::string> RunSpec::validate() const {
  std::vector<std::string> errors = run_config_errors(config, method.adaptive());
  // The path checks throw InputError; their messages join the list.
  try {
    check_run_outputs(config);
  } catch (const InputError& error) {
    errors.emplace_back(error.what());
  }
  try {
    check_optional_metrics(config.extra_metrics, "--metric");
  } catch (const InputError& error) {
    errors.emplace_back(error.what());
  }
  if (const Applicability fit = applicable(method.prototype(), *problem); !fit.ok) {
    errors.push_back(fit.reason);
  }
  if (!config.series_path.empty()) {
    if (std::string why = series_section_error(*problem, config.series_section); !why.empty()) {
      errors.push_back(std::move(why));
    }
  }
  return errors;
}

void throw_input_errors(const std::vector<std::string>& errors) {
  if (!errors.empty()) throw InputError(fmt::format("{}", fmt::join(errors, "; ")));
}

}  // namespace geomint
