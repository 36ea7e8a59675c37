// Reference files (see reference.hpp): where they live, loading them, and the error observer
// that compares a run with them at shared step points.
#include "harness/reference.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "harness/metrics.hpp"
#include "harness/paths.hpp"
#include "harness/table.hpp"
#include "integrators/newton.hpp"

namespace geomint {
namespace {

// Error against a reference row (see make_reference_observer).
class ReferenceErrorObserver : public Observer {
 public:
  explicit ReferenceErrorObserver(std::shared_ptr<const ReferenceSolution> reference)
      : reference_(std::move(reference)) {}
  void begin(const Problem&, const State& state, double t_end) override {
    t_last_ = state.t + t_end;
  }
  void observe(const Problem&, const State& state) override {
    const int row = reference_->row_at(state.t);
    if (row < 0) return;
    const double error = robust_norm(state.q - reference_->q[row], state.p - reference_->p[row]);
    error_max_ = std::max(error_max_, error);
    if (reference_->row_at(t_last_) == row) {
      error_final_ = error;
      reached_end_ = true;
    }
  }
  void finish(std::map<std::string, double>& metrics) const override {
    if (!reached_end_) return;
    metrics[metric::error_max.key()] = error_max_;
    metrics[metric::error_final.key()] = error_final_;
  }

 private:
  std::shared_ptr<const ReferenceSolution> reference_;
  double t_last_ = 0, error_max_ = 0, error_final_ = 0;
  bool reached_end_ = false;
};

}  // namespace

std::string reference_path(const std::string& dir, const Problem& problem) {
  std::string name = sanitize_for_path(problem.spec());
  // File systems refuse names over 255 bytes, which a long spec (rod_chain:n=64 lists 64
  // angles) exceeds: keep a readable prefix and make it unique with a hash of the whole name.
  // Every shorter name, and so every committed reference, is unchanged.
  constexpr std::size_t kMaxStem = 200;
  if (name.size() > kMaxStem) {
    std::uint64_t hash = 14695981039346656037ull;  // FNV-1a, 64 bit: stable across builds
    for (const unsigned char c : name) hash = (hash ^ c) * 1099511628211ull;
    name = fmt::format("{}_{:016x}", name.substr(0, kMaxStem - 17), hash);
  }
  return (std::filesystem::path(dir) / (name + ".csv")).string();
}

int ReferenceSolution::row_at(double t) const {
  const double tolerance = 1e-9 * std::max(1.0, std::abs(t));
  auto it = std::lower_bound(times.begin(), times.end(), t - tolerance);
  if (it == times.end() || std::abs(*it - t) > tolerance) return -1;
  return static_cast<int>(it - times.begin());
}

std::shared_ptr<const ReferenceSolution> load_reference(const std::string& path,
                                                        const Problem& problem) {
  std::ifstream file(path);
  if (!file) throw InputError(fmt::format("reference file '{}' cannot be read", path));
  std::stringstream buffer;
  buffer << file.rdbuf();
  const std::string text = buffer.str();
  auto fail = [&path](const std::string& what) {
    return InputError(fmt::format(
        "reference file '{}' is not a valid reference ({}); regenerate it with `geomint "
        "reference`",
        path, what));
  };

  // A file cut short is refused before any of its lines is believed.
  std::vector<Row> rows;
  try {
    rows = parse_csv(text);  // fail() names the file
  } catch (const std::exception& error) {
    throw fail(error.what());
  }
  auto solution = std::make_shared<ReferenceSolution>();
  solution->path = path;
  bool has_error = false;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("# ", 0) != 0) continue;
    const auto colon = line.find(": ");
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(2, colon - 2), value = line.substr(colon + 2);
    if (key == "reference_problem") solution->problem_spec = value;
    if (key == "estimated_error_max") {
      char* end = nullptr;
      solution->estimated_error = std::strtod(value.c_str(), &end);
      has_error = end != value.c_str() && *end == '\0';
    }
  }
  if (solution->problem_spec.empty()) throw fail("no '# reference_problem:' line");
  if (solution->problem_spec != problem.spec()) {
    throw fail(
        fmt::format("it is for problem '{}', not '{}'", solution->problem_spec, problem.spec()));
  }
  if (!has_error) throw fail("no numeric '# estimated_error_max:' line");

  if (rows.empty()) throw fail("no rows");
  const int dof = problem.dof();
  for (size_t r = 0; r < rows.size(); ++r) {
    auto value = [&](const std::string& column) {
      const auto it = rows[r].find(column);
      if (it == rows[r].end()) throw fail(fmt::format("row {} has no column '{}'", r + 1, column));
      char* end = nullptr;
      const double v = std::strtod(it->second.c_str(), &end);
      if (end == it->second.c_str() || *end != '\0' || !std::isfinite(v)) {
        throw fail(fmt::format("row {} column '{}' is not a finite number: '{}'", r + 1, column,
                               it->second));
      }
      return v;
    };
    if (rows[r].size() != static_cast<size_t>(1 + 2 * dof)) {
      throw fail(fmt::format("row {} has {} columns, expected t, q_0..q_{}, p_0..p_{}", r + 1,
                             rows[r].size(), dof - 1, dof - 1));
    }
    const double t = value("t");
    if (!solution->times.empty() && !(t > solution->times.back())) {
      throw fail(fmt::format("times are not increasing at row {}", r + 1));
    }
    Vec q(dof), p(dof);
    for (int i = 0; i < dof; ++i) {
      q[i] = value(fmt::format("q_{}", i));
      p[i] = value(fmt::format("p_{}", i));
    }
    solution->times.push_back(t);
    solution->q.push_back(std::move(q));
    solution->p.push_back(std::move(p));
  }
  return solution;
}

std::unique_ptr<Observer> make_reference_observer(
    std::shared_ptr<const ReferenceSolution> reference) {
  return std::make_unique<ReferenceErrorObserver>(std::move(reference));
}

}  // namespace geomint
