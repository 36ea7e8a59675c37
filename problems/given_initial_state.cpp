// Any problem started from a state read from a CSV file (the spec key `initial=FILE.csv`, which
// make_problem handles for every problem, and `geomint run|order --initial FILE.csv`;
// docs/PROBLEMS.md "Problems"): the problem is forwarded unchanged except for its initial state and
// the exact solution and period, which belong to the problem's own start.
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

class GivenInitialState final : public Problem {
 public:
  GivenInitialState(std::unique_ptr<Problem> base, State initial)
      : base_(std::move(base)), initial_(std::move(initial)) {
    set_mass(base_->mass());
    // The exact solution, period and tabulated end state belong to the problem's own start.
    set_capabilities(base_->capabilities() & ~(kExact | kPeriod | kEndReference));
    set_defaults(base_->default_dt(), base_->default_t_end());
  }

  State initial_state() const override { return initial_; }
  double potential(const Vec& q) const override { return base_->potential(q); }
  void gradient(const Vec& q, Vec& g) const override { base_->gradient(q, g); }
  FixedGradient fixed_gradient() const override { return base_->fixed_gradient(); }
  void hessian(const Vec& q, SparseMatrix& H) const override { base_->hessian(q, H); }
  void force(const Vec& q, const Vec& v, double t, Vec& f) const override {
    base_->force(q, v, t, f);
  }
  void force_jacobian_v(const Vec& q, const Vec& v, double t, SparseMatrix& C) const override {
    base_->force_jacobian_v(q, v, t, C);
  }
  Vec linear_momentum(const Vec& q, const Vec& p) const override {
    return base_->linear_momentum(q, p);
  }
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    return base_->angular_momentum(q, p);
  }
  double omega_max(const Vec& q) const override { return base_->omega_max(q); }
  double period_observable(const Vec& q, const Vec& p) const override {
    return base_->period_observable(q, p);
  }
  int constraint_count() const override { return base_->constraint_count(); }
  void constraint(const Vec& q, Vec& g) const override { base_->constraint(q, g); }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    base_->constraint_jacobian(q, G);
  }
  void constraint_curvature(const Vec& q, const Vec& v, Vec& c) const override {
    base_->constraint_curvature(q, v, c);
  }
  void constraint_hessian(const Vec& q, const Vec& lambda, SparseMatrix& K) const override {
    base_->constraint_hessian(q, lambda, K);
  }
  std::vector<std::string> multiplier_names() const override { return base_->multiplier_names(); }
  void constraint_at(double t, const Vec& q, Vec& g) const override {
    base_->constraint_at(t, q, g);
  }
  void constraint_jacobian_at(double t, const Vec& q, SparseMatrix& G) const override {
    base_->constraint_jacobian_at(t, q, G);
  }
  void constraint_time_terms(double t, const Vec& q, const Vec& v, Vec& g_t,
                             Vec& a_t) const override {
    base_->constraint_time_terms(t, q, v, g_t, a_t);
  }
  std::vector<std::string> series_names() const override { return base_->series_names(); }
  void series_values(const Vec& q, const Vec& p, std::vector<double>& values) const override {
    base_->series_values(q, p, values);
  }

 private:
  std::unique_ptr<Problem> base_;
  State initial_;
};

// Rows "q,p" (or "q,v" when the header says v), one per degree of freedom in the problem's
// order; an optional header line "q,p" or "q,v"; blank lines and '#' comments skipped.
State read_initial_state(const Problem& problem, const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("initial state: file '{}' cannot be read", path));
  std::vector<double> first, second;
  bool velocities = false;
  std::string line;
  int line_number = 0;
  bool seen_row = false;
  while (std::getline(in, line)) {
    ++line_number;
    std::string compact;
    for (char c : line) {
      if (c != ' ' && c != '\t' && c != '\r') compact += c;
    }
    if (compact.empty() || compact[0] == '#') continue;
    if (!seen_row && (compact == "q,p" || compact == "q,v")) {
      velocities = compact == "q,v";
      seen_row = true;
      continue;
    }
    seen_row = true;
    const auto comma = compact.find(',');
    double values[2];
    for (int column = 0; column < 2; ++column) {
      const std::string field = column == 0                  ? compact.substr(0, comma)
                                : comma == std::string::npos ? std::string()
                                                             : compact.substr(comma + 1);
      char* end = nullptr;
      values[column] = std::strtod(field.c_str(), &end);
      if (field.empty() || end != field.c_str() + field.size() || !std::isfinite(values[column])) {
        throw InputError(fmt::format(
            "initial state: {}:{}: expected two finite numbers q,p (or q,v under a 'q,v' header), "
            "got '{}'",
            path, line_number, line));
      }
    }
    first.push_back(values[0]);
    second.push_back(values[1]);
  }
  const int n = problem.dof();
  if (static_cast<int>(first.size()) != n) {
    throw InputError(fmt::format(
        "initial state: {} has {} rows; problem '{}' has n = {} degrees of freedom (one q,p row "
        "each)",
        path, first.size(), problem.spec(), n));
  }
  State state;
  state.t = problem.initial_state().t;
  state.q = Eigen::Map<const Vec>(first.data(), n);
  state.p = Eigen::Map<const Vec>(second.data(), n);
  if (velocities) state.p = problem.mass().cwiseProduct(state.p);
  return state;
}

}  // namespace

std::unique_ptr<Problem> with_initial_state_file(std::unique_ptr<Problem> problem,
                                                 const std::string& path) {
  if (problem->has(kFirstOrderOnly)) {
    throw InputError(
        fmt::format("initial state: problem '{}' is a first-order ODE y' = f(t, y); "
                    "initial= (q,p rows) applies to Lagrangian problems only",
                    problem->name()));
  }
  // The forwarding wrapper has no LagrangianSystem: a non-separable problem would silently run
  // with its placeholder unit mass.
  if (is_non_separable(*problem)) {
    throw InputError(
        fmt::format("initial state: problem '{}' has a position-dependent mass M(q) "
                    "(non_separable); initial= applies to constant-mass problems only",
                    problem->name()));
  }
  State initial = read_initial_state(*problem, path);
  return std::make_unique<GivenInitialState>(std::move(problem), std::move(initial));
}

}  // namespace geomint
