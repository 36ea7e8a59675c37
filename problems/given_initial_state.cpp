// Any problem started from a state read from a CSV file (the spec key `initial=FILE.csv`, which
// make_problem handles for every problem, and `geomint run|order --initial FILE.csv`;
// docs/PROBLEMS.md "Problems"): the problem is forwarded unchanged except for its initial state and
// the exact solution and period, which belong to the problem's own start.
#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <fstream>
#include <sstream>

#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"
#include "problems/structures/charged_particle.hpp"
#include "problems/structures/time_dependent.hpp"

namespace geomint {
namespace {

class GivenInitialState : public Problem, public HolonomicConstraints {
 public:
  GivenInitialState(std::unique_ptr<Problem> base, State initial)
      : base_(std::move(base)),
        base_constraints_(base_->as_constrained()),
        initial_(std::move(initial)) {
    // The base's constant mass if it has one (the kSeparable kind), else only its dof.
    if (base_->kind() == ProblemKind::kSeparable) {
      set_mass(base_->mass());
    } else {
      set_dof(base_->dof());
    }
    // The exact solution, period and tabulated end state belong to the problem's own start;
    // the constraint and force capabilities follow from as_constrained() and as_forced() below.
    set_capabilities(base_->capabilities() &
                     ~(kExact | kPeriod | kEndReference | kDerivedCapabilities));
    set_defaults(base_->default_dt(), base_->default_t_end());
  }

  State initial_state() const override { return initial_; }
  double potential(const Vec& q) const override { return base_->potential(q); }
  void gradient(const Vec& q, Vec& g) const override { base_->gradient(q, g); }
  FixedGradient fixed_gradient() const override { return base_->fixed_gradient(); }
  void hessian(const Vec& q, SparseMatrix& H) const override { base_->hessian(q, H); }
  // The base's force (and its Jacobian) as they are: they do not depend on the start.
  const NonConservativeForce* as_forced() const override { return base_->as_forced(); }
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
  // The base's constraints, except its exact multipliers (they belong to its own start, like
  // exact(): the default nullopt), so the wrapper is its own HolonomicConstraints.
  const HolonomicConstraints* as_constrained() const override {
    return base_constraints_ != nullptr ? this : nullptr;
  }
  int constraint_count() const override {
    return base_constraints_ != nullptr ? base_constraints_->constraint_count() : 0;
  }
  void constraint(const Vec& q, Vec& g) const override { base_constraints_->constraint(q, g); }
  void constraint_jacobian(const Vec& q, SparseMatrix& G) const override {
    base_constraints_->constraint_jacobian(q, G);
  }
  void constraint_curvature(const Vec& q, const Vec& v, Vec& c) const override {
    base_constraints_->constraint_curvature(q, v, c);
  }
  void constraint_hessian(const Vec& q, const Vec& lambda, SparseMatrix& K) const override {
    base_constraints_->constraint_hessian(q, lambda, K);
  }
  std::vector<std::string> multiplier_names() const override {
    return base_constraints_->multiplier_names();
  }
  bool time_dependent() const override { return base_constraints_->time_dependent(); }
  void constraint_at(double t, const Vec& q, Vec& g) const override {
    base_constraints_->constraint_at(t, q, g);
  }
  void constraint_jacobian_at(double t, const Vec& q, SparseMatrix& G) const override {
    base_constraints_->constraint_jacobian_at(t, q, G);
  }
  void constraint_time_terms(double t, const Vec& q, const Vec& v, Vec& g_t,
                             Vec& a_t) const override {
    base_constraints_->constraint_time_terms(t, q, v, g_t, a_t);
  }
  // A charged particle's mass, charge, fields and vector potential do not depend on its start:
  // the Boris pusher and the magnetic-moment metric keep them. Nor does a time-dependent H(q, p,
  // t), without which the wrapper would pass for the time-free H(q, p, 0).
  const void* structure(const StructureKey& key) const override {
    if (&key == &ChargedParticleStructure::kStructureKey ||
        &key == &TimeDependentHamiltonian::kStructureKey) {
      return base_->structure(key);
    }
    return nullptr;
  }
  std::vector<std::string> series_names() const override { return base_->series_names(); }
  void series_values(const Vec& q, const Vec& p, std::vector<double>& values) const override {
    base_->series_values(q, p, values);
  }

 protected:
  const Problem& base() const { return *base_; }

 private:
  std::unique_ptr<Problem> base_;
  const HolonomicConstraints* base_constraints_;  // base_->as_constrained(), or nullptr
  State initial_;
};

// A non-separable problem from a file: the forwarding above plus the base's LagrangianSystem, so
// that energy(), first_order_rhs() and the general integrators see its M(q), a(q) and V (it has
// no constant mass; docs/MECHANICS_GENERAL.md §8, the paragraph on initial=).
class GivenInitialLagrangian final : public GivenInitialState, public LagrangianSystem {
 public:
  GivenInitialLagrangian(std::unique_ptr<Problem> base, State initial)
      : GivenInitialState(std::move(base), std::move(initial)),
        system_(*GivenInitialState::base().as_lagrangian()) {}
  const LagrangianSystem* as_lagrangian() const override { return this; }

  void mass_matrix(const Vec& q, DenseMatrix& M) const override { system_.mass_matrix(q, M); }
  void kinetic_gradient(const Vec& q, const Vec& v, Vec& T_q) const override {
    system_.kinetic_gradient(q, v, T_q);
  }
  void mass_velocity_jacobian(const Vec& q, const Vec& v, DenseMatrix& D) const override {
    system_.mass_velocity_jacobian(q, v, D);
  }
  void kinetic_hessian(const Vec& q, const Vec& v, DenseMatrix& T_qq) const override {
    system_.kinetic_hessian(q, v, T_qq);
  }
  void gyroscopic(const Vec& q, Vec& a) const override { system_.gyroscopic(q, a); }
  void gyroscopic_jacobian(const Vec& q, DenseMatrix& A) const override {
    system_.gyroscopic_jacobian(q, A);
  }
  void gyroscopic_hessian(const Vec& q, const Vec& v, DenseMatrix& a_qq) const override {
    system_.gyroscopic_hessian(q, v, a_qq);
  }
  // The base's own (possibly O(n)) mass operator and gyroscopic force, not the dense defaults.
  void add_gyroscopic_force(const Vec& q, const Vec& v, Vec& L_q) const override {
    system_.add_gyroscopic_force(q, v, L_q);
  }
  void apply_mass(const Vec& q, const Vec& v, Vec& Mv) const override {
    system_.apply_mass(q, v, Mv);
  }
  void solve_mass(const Vec& q, const Vec& p, Vec& v) const override {
    system_.solve_mass(q, p, v);
  }
  bool mass_is_recursive() const override { return system_.mass_is_recursive(); }
  void solve_mass_with_stiffness(const Vec& q, double c, const Vec& r, Vec& x) const override {
    system_.solve_mass_with_stiffness(q, c, r, x);
  }
  // One override each for Problem's and LagrangianSystem's V and ∇V (the same functions).
  double potential(const Vec& q) const override { return system_.potential(q); }
  void gradient(const Vec& q, Vec& g) const override { system_.gradient(q, g); }
  void potential_hessian(const Vec& q, DenseMatrix& K) const override {
    system_.potential_hessian(q, K);
  }

 private:
  const LagrangianSystem& system_;
};

// A start where M(q) is not positive definite (a coordinate singularity: the spherical pendulum's
// pole in angles, r = 0 in polar coordinates) has no velocity v = M⁻¹(p − a): an input error, as
// for the problems' own parameters, rather than a NaN first step.
void check_general_start(const LagrangianSystem& system, const Problem& problem, const State& state,
                         const std::string& path) {
  DenseMatrix M;
  system.mass_matrix(state.q, M);
  Eigen::LLT<DenseMatrix> cholesky(M);
  if (!M.allFinite() || cholesky.info() != Eigen::Success ||
      !std::isfinite(system.hamiltonian(state.q, state.p))) {
    throw InputError(fmt::format(
        "initial state: {}: the mass matrix M(q) of problem '{}' is not positive definite at the "
        "given q (a coordinate singularity, such as a pole of the angles or r = 0); allowed: a q "
        "where M(q) is positive definite",
        path, problem.spec()));
  }
}

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
  for (const Problem::PositiveCoordinate& coordinate : problem.positive_coordinates()) {
    const double value = first[coordinate.index];
    if (!(value > 0)) {
      throw InputError(fmt::format(
          "initial state: {}: row {}: q = {} is out of range for {} of problem '{}' (allowed: > 0)",
          path, coordinate.index + 1, format_number(value), coordinate.name, problem.spec()));
    }
  }
  State state;
  state.t = problem.initial_state().t;
  state.q = Eigen::Map<const Vec>(first.data(), n);
  state.p = Eigen::Map<const Vec>(second.data(), n);
  // Canonical p = M(q)v + a(q) (a constant diagonal M and a = 0 on a separable problem).
  if (const LagrangianSystem* system = problem.as_lagrangian()) {
    if (velocities) state.p = system->momentum(state.q, state.p);
    check_general_start(*system, problem, state, path);
  } else if (velocities) {
    state.p = problem.mass().cwiseProduct(state.p);
  }
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
  State initial = read_initial_state(*problem, path);
  if (problem->kind() == ProblemKind::kLagrangian) {
    return std::make_unique<GivenInitialLagrangian>(std::move(problem), std::move(initial));
  }
  return std::make_unique<GivenInitialState>(std::move(problem), std::move(initial));
}

}  // namespace geomint
