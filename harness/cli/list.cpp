// `geomint list [methods|problems|all|NAME] [--markdown]`: the registries as aligned columns with
// every parameter's default, as the README's Markdown tables, or one method or problem with its
// parameters, their defaults and the ranges Params enforces (docs/CLI.md "list").
#include <fmt/format.h>

#include <algorithm>
#include <memory>

#include "harness/cli/verbs.hpp"
#include "integrators/integrator.hpp"
#include "integrators/time_treatment.hpp"
#include "problems/problem.hpp"

namespace geomint::cli {
namespace {

struct ListOptions {
  std::string what = "all";
  bool markdown = false;
};

std::string parameter_list(const Params& params) {
  std::vector<std::string> parameters;
  for (const auto& doc : params.docs()) {
    parameters.push_back(fmt::format("{}={}", doc.key, doc.default_value));
  }
  return fmt::format("{}", fmt::join(parameters, ","));
}

// A Markdown table cell: '|' would end the cell.
std::string markdown_cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

// The default configuration's order, then the other orders among the variants the tests cover
// (integrators/registry.def): "2 (variants: 1)" for hp.
std::string order_column(const IntegratorEntry& entry, int default_order) {
  std::vector<int> others;
  for (const auto& variant : entry.variants) {
    const int order = make_integrator(entry.name + ":" + variant)->info().order;
    if (order != default_order && std::find(others.begin(), others.end(), order) == others.end()) {
      others.push_back(order);
    }
  }
  if (others.empty()) return std::to_string(default_order);
  std::sort(others.begin(), others.end());
  return fmt::format("{} (variants: {})", default_order, fmt::join(others, ", "));
}

// Aligned plain-text columns: each as wide as its widest cell (names and capability lists grow
// with the registry, so fixed widths let a long one push the rest of its row out of line). The
// last column is left unpadded.
void print_aligned(const std::vector<std::vector<std::string>>& rows,
                   const std::vector<bool>& right_aligned) {
  std::vector<std::size_t> widths(right_aligned.size(), 0);
  for (const auto& row : rows) {
    for (std::size_t column = 0; column < row.size(); ++column) {
      widths[column] = std::max(widths[column], row[column].size());
    }
  }
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t column = 0; column < row.size(); ++column) {
      const bool last = column + 1 == row.size();
      if (column > 0) line += column == 2 ? "  " : " ";
      if (last) {
        line += row[column];
      } else if (right_aligned[column]) {
        line += fmt::format("{:>{}}", row[column], widths[column]);
      } else {
        line += fmt::format("{:<{}}", row[column], widths[column]);
      }
    }
    line.erase(line.find_last_not_of(' ') + 1);  // an empty last column leaves no padding
    fmt::print("{}\n", line);
  }
}

// `markdown`: the README's table (README.md, between <!-- methods:begin/end -->), one row per
// built-in registry entry (register_method() ones are not the README's); otherwise aligned
// columns with every parameter and its default, registered methods included.
void print_methods(bool markdown) {
  std::vector<std::vector<std::string>> rows;
  if (markdown) {
    fmt::print(
        "| method | provider | order | flags | time | what it is |\n|---|---|---|---|---|---|\n");
  } else {
    rows.push_back({"method", "provider", "order", "flags", "time", "parameters (default)"});
  }
  for (const auto& entry : integrator_registry()) {
    if (markdown && !entry.builtin) continue;
    Params params(Spec{entry.name, {}}, entry.name);
    const auto integrator = entry.factory(params);
    const MethodInfo info = integrator->info();
    if (markdown) {
      fmt::print("| `{}` | {} | {} | {} | {} | {} |\n", entry.name, entry.provider.label(),
                 order_column(entry, info.order),
                 fmt::format("{}", fmt::join(flag_names(info.flags), ", ")),
                 time_treatment_name(time_treatment(*integrator)), markdown_cell(entry.summary));
    } else {
      rows.push_back({entry.name, entry.provider.label(), std::to_string(info.order),
                      fmt::format("{}", fmt::join(flag_names(info.flags), ",")),
                      time_treatment_name(time_treatment(*integrator)), parameter_list(params)});
    }
  }
  if (!markdown) print_aligned(rows, {false, false, true, false, false, false});
}

// The integer parameters with their ranges ("`n` 1..64"): the size limits a reader of the table
// needs before writing a spec; the real parameters' ranges are in `geomint list NAME`.
std::string integer_limits(const Params& params) {
  std::vector<std::string> limits;
  for (const auto& doc : params.docs()) {
    if (doc.kind == "integer") limits.push_back(fmt::format("`{}` {}", doc.key, doc.allowed));
  }
  return fmt::format("{}", fmt::join(limits, ", "));
}

void print_problems(bool markdown) {
  std::vector<std::vector<std::string>> rows;
  if (markdown) {
    fmt::print(
        "| problem | dof | capabilities | integer parameters | what it is |\n"
        "|---|---|---|---|---|\n");
  } else {
    rows.push_back({"problem", "dof", "capabilities (defaults)", "parameters (default)"});
  }
  for (const auto& entry : problem_registry()) {
    if (markdown && !entry.builtin) continue;
    Params params(Spec{entry.name, {}}, entry.name);
    const auto problem = entry.factory(params);
    const auto capabilities = capability_names(problem->capabilities());
    if (markdown) {
      fmt::print("| `{}` | {} | {} | {} | {} |\n", entry.name, problem->dof(),
                 fmt::format("{}", fmt::join(capabilities, ", ")), integer_limits(params),
                 markdown_cell(entry.summary));
    } else {
      // "none" keeps the column aligned (damped_harmonic_td declares no capability).
      rows.push_back({entry.name, std::to_string(problem->dof()),
                      capabilities.empty() ? std::string("none")
                                           : fmt::format("{}", fmt::join(capabilities, ",")),
                      parameter_list(params)});
    }
  }
  if (!markdown) print_aligned(rows, {false, true, false, false});
}

// One parameter per row: key, kind, default, what is allowed (the Range Params checks), help.
void print_parameters(const Params& params) {
  std::vector<std::vector<std::string>> rows = {
      {"parameter", "kind", "default", "allowed", "help"}};
  for (const auto& doc : params.docs()) {
    std::string allowed = doc.allowed;
    const bool bounded = doc.range && doc.range->min >= -kMaxParameterMagnitude &&
                         doc.range->max <= kMaxParameterMagnitude;
    if (doc.kind == "real" && !bounded) {
      // Every real parameter is bounded in magnitude as well (Params::real).
      const std::string bound = fmt::format("|{}| <= {:g}", doc.key, kMaxParameterMagnitude);
      allowed = allowed.empty() ? bound : allowed + ", " + bound;
    }
    rows.push_back({doc.key, doc.kind, doc.default_value.empty() ? "(none)" : doc.default_value,
                    allowed, doc.help});
  }
  if (rows.size() == 1) {
    fmt::print("parameters: none\n");
  } else {
    print_aligned(rows, {false, false, false, false, false});
  }
}

// `geomint list NAME`: the entry named NAME (a method, a problem, or both when both registries
// have it); InputError with the close names otherwise.
void print_entry(const std::string& name) {
  bool found = false;
  for (const auto& entry : integrator_registry()) {
    if (entry.name != name) continue;
    Params params(Spec{entry.name, {}}, entry.name);
    const auto integrator = entry.factory(params);
    const MethodInfo info = integrator->info();
    fmt::print("{} (method): {}\nprovider {}; order {}; flags: {}; time: {}\n\n", entry.name,
               entry.summary, entry.provider.label(), order_column(entry, info.order),
               fmt::join(flag_names(info.flags), ", "),
               time_treatment_name(time_treatment(*integrator)));
    print_parameters(params);
    found = true;
  }
  for (const auto& entry : problem_registry()) {
    if (entry.name != name) continue;
    if (found) fmt::print("\n");
    Params params(Spec{entry.name, {}}, entry.name);
    const auto problem = entry.factory(params);
    fmt::print("{} (problem): {}\ndof {} (with the defaults); capabilities: {}\n\n", entry.name,
               entry.summary, problem->dof(),
               fmt::join(capability_names(problem->capabilities()), ", "));
    print_parameters(params);
    found = true;
  }
  if (found) return;
  std::vector<std::string> names = {"methods", "problems", "all"};
  for (const auto& entry : integrator_registry()) names.push_back(entry.name);
  for (const auto& entry : problem_registry()) names.push_back(entry.name);
  throw InputError(fmt::format(
      "list: '{}' is neither a method nor a problem{} (allowed: methods, problems, all, or a name "
      "that `geomint list` shows)",
      name, did_you_mean(name, names)));
}

int run_list(const ListOptions& options) {
  if (options.what != "methods" && options.what != "problems" && options.what != "all") {
    if (options.markdown) {
      throw InputError("list: --markdown goes with methods, problems or all, not with one name");
    }
    print_entry(options.what);
    return kExitOk;
  }
  if (options.what != "problems") print_methods(options.markdown);
  if (options.what == "all") fmt::print("\n");
  if (options.what != "methods") print_problems(options.markdown);
  return kExitOk;
}

}  // namespace

Verb add_list(CLI::App& app) {
  auto options = std::make_shared<ListOptions>();
  auto* command = app.add_subcommand("list", "List registered methods and/or problems");
  command->add_option("what", options->what,
                      "methods | problems | all | NAME (one method or problem: its description, "
                      "parameters, their defaults and allowed ranges)");
  command->add_flag("--markdown", options->markdown,
                    "print the README's Markdown tables (methods: order, flags, summary; "
                    "problems: dof, capabilities of the defaults, summary); `make readme-tables` "
                    "pastes them");
  return {"list", command, [options](const Context&) { return run_list(*options); }};
}

}  // namespace geomint::cli
