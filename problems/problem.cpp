// Problem base-class defaults, the first-order view for ODE solvers, and the problem registry.
#include "problems/problem.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <limits>

#include "problems/first_order.hpp"
#include "problems/force.hpp"
#include "problems/lagrangian.hpp"
#include "problems/structures/time_dependent.hpp"

namespace geomint {

#define GEOMINT_PROBLEM(name, factory, variants, summary) std::unique_ptr<Problem> factory(Params&);
#include "problems/registry.def"
#undef GEOMINT_PROBLEM

namespace {
// Function-local static: safe to extend from another translation unit's static initialiser.
std::vector<ProblemEntry>& mutable_problem_registry() {
  static std::vector<ProblemEntry> entries = {
#define GEOMINT_PROBLEM(name, factory, variants, summary) \
  {#name, summary, &factory, split_variants(variants)},
#include "problems/registry.def"
#undef GEOMINT_PROBLEM
  };
  return entries;
}
}  // namespace

const std::vector<ProblemEntry>& problem_registry() { return mutable_problem_registry(); }

void register_problem(ProblemEntry entry) {
  auto& entries = mutable_problem_registry();
  check_registration_name(entry.name, "problem");
  if (entry.factory == nullptr) {
    throw InputError(fmt::format("register_problem: problem '{}' has no factory", entry.name));
  }
  for (const auto& existing : entries) {
    if (existing.name == entry.name) {
      throw InputError(fmt::format("register_problem: a problem named '{}' is already registered{}",
                                   entry.name, existing.builtin ? " (built-in)" : ""));
    }
  }
  entry.builtin = false;
  entries.push_back(std::move(entry));
}

std::vector<std::string> problem_test_specs() {
  std::vector<std::string> specs;
  for (const auto& entry : problem_registry()) {
    specs.push_back(entry.name);
    for (const auto& variant : entry.variants) specs.push_back(entry.name + ":" + variant);
  }
  return specs;
}

// problems/given_initial_state.cpp
std::unique_ptr<Problem> with_initial_state_file(std::unique_ptr<Problem> problem,
                                                 const std::string& path);

std::unique_ptr<Problem> make_problem(const std::string& spec_text) {
  notify_spec_parse(spec_text);
  Spec spec = Spec::parse(spec_text);
  // `initial=FILE.csv` belongs to every problem: it replaces the start after construction.
  std::string initial_file;
  if (const auto it = spec.values.find(kInitialStateKey); it != spec.values.end()) {
    initial_file = it->second;
    spec.values.erase(it);
  }
  std::vector<std::string> names;
  for (const auto& entry : problem_registry()) {
    if (entry.name != spec.name) {
      names.push_back(entry.name);
      continue;
    }
    Params params(spec, fmt::format("problem '{}'", spec.name));
    auto problem = entry.factory(params);
    params.finish();
    problem->name_ = entry.name;
    problem->spec_ = params.canonical();
    if (!initial_file.empty()) {
      problem = with_initial_state_file(std::move(problem), initial_file);
      problem->name_ = entry.name;
      Spec canonical = Spec::parse(params.canonical());
      canonical.values[kInitialStateKey] = initial_file;
      problem->spec_ = entry.name;
      char separator = ':';
      for (const auto& [key, value] : canonical.values) {
        problem->spec_ += separator + key + "=" + value;
        separator = ',';
      }
    }
    if (problem->has(kConstraints))
      problem->check_consistent(problem->initial_state(), "initial state");
    return problem;
  }
  throw InputError(fmt::format("unknown problem '{}'{} (valid: {})", spec.name,
                               did_you_mean(spec.name, names), fmt::join(names, ", ")));
}

std::vector<std::string> capability_names(unsigned capabilities) {
  static const std::pair<Capability, const char*> kNames[] = {
      {kHessian, "hessian"},
      {kForce, "force"},
      {kExact, "exact"},
      {kLinearMomentum, "linear_momentum"},
      {kAngularMomentum, "angular_momentum"},
      {kPeriod, "period"},
      {kOmegaMax, "omega_max"},
      {kForceJacobian, "force_jacobian"},
      {kConstraints, "constraints"},
      {kTimeDependentConstraints, "time_dependent_constraints"},
      {kFirstOrderOnly, "first_order_only"},
      {kEndReference, "end_reference"},
      {kCasimir, "casimir"},
  };
  std::vector<std::string> out;
  for (const auto& [bit, label] : kNames) {
    if (capabilities & bit) out.emplace_back(label);
  }
  return out;
}

const char* kind_name(ProblemKind kind) {
  switch (kind) {
    case ProblemKind::kFirstOrder:
      return "first_order";
    case ProblemKind::kSeparable:
      return "separable";
    case ProblemKind::kLagrangian:
      return "lagrangian";
  }
  return "unknown";
}

ProblemKind Problem::kind() const {
  if (as_first_order() != nullptr) return ProblemKind::kFirstOrder;
  if (as_lagrangian() != nullptr) return ProblemKind::kLagrangian;
  return ProblemKind::kSeparable;
}

namespace {
// The LagrangianSystem of a problem that is_non_separable (callers check).
const LagrangianSystem& general_system(const Problem& problem) { return *problem.as_lagrangian(); }

[[noreturn]] void missing(const Problem& problem, const char* what) {
  throw std::logic_error(fmt::format("problem '{}' has no {}", problem.name(), what));
}
}  // namespace

void Problem::hessian(const Vec&, SparseMatrix&) const { missing(*this, "hessian"); }
double Problem::casimir(const Vec&, const Vec&) const { missing(*this, "casimir"); }
void NonConservativeForce::force_jacobian_v(const Vec&, const Vec&, double, SparseMatrix&) const {
  throw std::logic_error(
      "NonConservativeForce::force_jacobian_v: this force has no Jacobian (has_force_jacobian() "
      "is false, so the problem lacks kForceJacobian)");
}
State Problem::exact(double) const { missing(*this, "exact solution"); }
Vec Problem::linear_momentum(const Vec&, const Vec&) const { missing(*this, "linear momentum"); }
Vec Problem::angular_momentum(const Vec&, const Vec&) const { missing(*this, "angular momentum"); }
double Problem::period() const { missing(*this, "period"); }
double Problem::period_observable(const Vec& q, const Vec&) const { return q[0]; }
double Problem::omega_max(const Vec&) const { missing(*this, "omega_max"); }
unsigned Problem::capabilities() const {
  unsigned derived = 0;
  if (const HolonomicConstraints* constraints = as_constrained()) {
    derived |= kConstraints;
    if (constraints->time_dependent()) derived |= kTimeDependentConstraints;
  }
  if (as_first_order() != nullptr) derived |= kFirstOrderOnly;
  if (const NonConservativeForce* forced = as_forced()) {
    derived |= kForce;
    if (forced->has_force_jacobian()) derived |= kForceJacobian;
  }
  return capabilities_ | derived;
}

bool Problem::has_derived(Capability c) const {
  switch (c) {
    case kFirstOrderOnly:
      return as_first_order() != nullptr;
    case kForce:
      return as_forced() != nullptr;
    case kForceJacobian: {
      const NonConservativeForce* forced = as_forced();
      return forced != nullptr && forced->has_force_jacobian();
    }
    case kConstraints:
      return as_constrained() != nullptr;
    case kTimeDependentConstraints: {
      const HolonomicConstraints* constraints = as_constrained();
      return constraints != nullptr && constraints->time_dependent();
    }
    default:
      return (capabilities() & c) != 0;
  }
}

void Problem::set_capabilities(unsigned capabilities) {
  if ((capabilities & kDerivedCapabilities) != 0) {
    throw std::logic_error(fmt::format(
        "Problem::set_capabilities: {} derived from the structure queries, not declared "
        "(kConstraints and kTimeDependentConstraints from as_constrained(), problems/"
        "constraints.hpp; kFirstOrderOnly from as_first_order(), problems/first_order.hpp; "
        "kForce and kForceJacobian from as_forced(), problems/force.hpp)",
        fmt::join(capability_names(capabilities & kDerivedCapabilities), ", ")));
  }
  capabilities_ = capabilities;
}

const NonConservativeForce& force_of(const Problem& problem) {
  const NonConservativeForce* forced = problem.as_forced();
  if (forced == nullptr) missing(problem, "force");
  return *forced;
}

const FirstOrderSystem& first_order_system_of(const Problem& problem) {
  const FirstOrderSystem* system = problem.as_first_order();
  if (system == nullptr) missing(problem, "first-order system y' = f(t, y)");
  return *system;
}

const HolonomicConstraints& constraints_of(const Problem& problem) {
  const HolonomicConstraints* constraints = problem.as_constrained();
  if (constraints == nullptr) missing(problem, "constraints");
  return *constraints;
}

// With M(q) the motion is d/dt(M v) = L_q + F − Gᵀλ, so M q̈ = L_q − Ṁv + F − Gᵀλ with Ṁv = D v
// (D = ∂(M v)/∂q, LagrangianSystem::mass_velocity_jacobian); d²g/dt² = 0 then gives
// (G M⁻¹ Gᵀ) λ = G M⁻¹ (L_q − D v + F) + c(q, v) + a_t, M⁻¹ by dense Cholesky.
namespace {
Vec general_multipliers(const Problem& problem, double t, const Vec& q, const Vec& p) {
  const LagrangianSystem& system = general_system(problem);
  const Vec v = system.velocity(q, p);
  Vec force_total;
  system.lagrangian_q(q, v, force_total);
  Eigen::MatrixXd D;
  system.mass_velocity_jacobian(q, v, D);
  force_total -= D * v;
  if (const NonConservativeForce* forced = problem.as_forced()) {
    Vec f;
    forced->force(q, v, t, f);
    force_total += f;
  }
  const HolonomicConstraints& constraints = constraints_of(problem);
  SparseMatrix G;
  constraints.constraint_jacobian_at(t, q, G);
  Vec c, g_t, a_t;
  constraints.constraint_curvature(q, v, c);
  constraints.constraint_time_terms(t, q, v, g_t, a_t);
  c += a_t;
  Eigen::MatrixXd M;
  system.mass_matrix(q, M);
  const Eigen::LLT<Eigen::MatrixXd> mass(M);
  const Eigen::MatrixXd Gdense(G);
  const Eigen::MatrixXd MinvGt = mass.solve(Gdense.transpose());
  const Eigen::MatrixXd S = Gdense * MinvGt;
  const Vec rhs = MinvGt.transpose() * force_total + c;
  return S.ldlt().solve(rhs);
}

// The velocity the constraint residuals use: M⁻¹p, or M(q)⁻¹(p − a(q)) on the kLagrangian kind.
Vec constraint_velocity(const Problem& problem, const Vec& q, const Vec& p) {
  if (problem.kind() == ProblemKind::kLagrangian) return general_system(problem).velocity(q, p);
  return problem.inverse_mass().cwiseProduct(p);
}
}  // namespace

Vec Problem::multipliers(double t, const Vec& q, const Vec& p) const {
  if (kind() == ProblemKind::kLagrangian) return general_multipliers(*this, t, q, p);
  const Vec v = inverse_mass().cwiseProduct(p);
  Vec force_total;
  gradient(q, force_total);
  force_total = -force_total;
  if (const NonConservativeForce* forced = as_forced()) {
    Vec f;
    forced->force(q, v, t, f);
    force_total += f;
  }
  const HolonomicConstraints& constraints = constraints_of(*this);
  SparseMatrix G;
  constraints.constraint_jacobian_at(t, q, G);
  Vec c, g_t, a_t;
  constraints.constraint_curvature(q, v, c);
  constraints.constraint_time_terms(t, q, v, g_t, a_t);
  c += a_t;
  // m is small for every catalogue problem (rods, pins), so a dense solve of G M⁻¹ Gᵀ is the
  // simplest correct choice; LDLT copes with the semidefinite case of redundant constraints.
  const Eigen::MatrixXd GMinv = Eigen::MatrixXd(G) * inverse_mass().asDiagonal();
  const Eigen::MatrixXd S = GMinv * Eigen::MatrixXd(G).transpose();
  const Vec rhs = GMinv * force_total + c;
  return S.ldlt().solve(rhs);
}

namespace {
void require_time_free(const Problem& problem) {
  if (problem.has(kTimeDependentConstraints)) {
    throw std::logic_error("problem '" + problem.spec() +
                           "' has time-dependent constraints: the residual needs the time t");
  }
}
}  // namespace

double Problem::constraint_residual(const Vec& q) const {
  require_time_free(*this);
  return constraint_residual(0.0, q);
}

double Problem::constraint_velocity_residual(const Vec& q, const Vec& p) const {
  require_time_free(*this);
  return constraint_velocity_residual(0.0, q, p);
}

double Problem::constraint_residual(double t, const Vec& q) const {
  Vec g;
  constraints_of(*this).constraint_at(t, q, g);
  return g.size() > 0 ? g.cwiseAbs().maxCoeff() : 0.0;
}

double Problem::constraint_velocity_residual(double t, const Vec& q, const Vec& p) const {
  const HolonomicConstraints& constraints = constraints_of(*this);
  SparseMatrix G;
  constraints.constraint_jacobian_at(t, q, G);
  const Vec v = constraint_velocity(*this, q, p);
  Vec g_t, a_t;
  constraints.constraint_time_terms(t, q, v, g_t, a_t);
  const Vec rate = G * v + g_t;
  return rate.size() > 0 ? rate.cwiseAbs().maxCoeff() : 0.0;
}

void Problem::check_consistent(const State& state, const std::string& what, double tol) const {
  SparseMatrix G;
  constraints_of(*this).constraint_jacobian_at(state.t, state.q, G);
  // ‖G‖∞: the largest absolute row sum, the scale that turns a position error into g.
  Vec row_sums = Vec::Zero(G.rows());
  for (int k = 0; k < G.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(G, k); it; ++it) row_sums[it.row()] += std::abs(it.value());
  }
  const double G_norm = row_sums.size() > 0 ? row_sums.maxCoeff() : 0.0;
  const Vec v = constraint_velocity(*this, state.q, state.p);
  const double q_norm = state.q.size() > 0 ? state.q.cwiseAbs().maxCoeff() : 0.0;
  const double v_norm = v.size() > 0 ? v.cwiseAbs().maxCoeff() : 0.0;
  const double position = constraint_residual(state.t, state.q);
  const double velocity = constraint_velocity_residual(state.t, state.q, state.p);
  const double position_allowed = tol * G_norm * q_norm;
  const double velocity_allowed = tol * G_norm * v_norm;
  if (!(position <= position_allowed)) {
    throw InputError(fmt::format(
        "problem '{}': inconsistent {}: constraint residual max|g(q)| = {:.3g} (allowed <= {:.3g}, "
        "{:g} relative to |G||q|); give a state on the constraint manifold",
        spec(), what, position, position_allowed, tol));
  }
  if (!(velocity <= velocity_allowed)) {
    throw InputError(fmt::format(
        "problem '{}': inconsistent {}: velocity constraint residual max|G(q) v| = {:.3g} (allowed "
        "<= {:.3g}, {:g} relative to |G||v|); give a velocity tangent to the constraint manifold",
        spec(), what, velocity, velocity_allowed, tol));
  }
}

void Problem::set_mass(const Vec& mass) {
  dof_ = static_cast<int>(mass.size());
  has_constant_mass_ = true;
  mass_ = mass;
  inverse_mass_ = mass.cwiseInverse();
}

void Problem::set_dof(int dof) {
  dof_ = dof;
  has_constant_mass_ = false;
  mass_.resize(0);
  inverse_mass_.resize(0);
}

void Problem::no_constant_mass() const {
  const ProblemKind problem_kind = kind();
  const char* instead = problem_kind == ProblemKind::kLagrangian
                            ? "use its LagrangianSystem (H, ∂H/∂p)"
                            : "use its FirstOrderSystem y' = f(t, y)";
  throw std::logic_error(
      fmt::format("problem '{}' is of kind {}: it has no constant mass matrix; {}", name(),
                  kind_name(problem_kind), instead));
}

double Problem::kinetic(const Vec& p) const { return 0.5 * p.dot(inverse_mass().cwiseProduct(p)); }

double Problem::energy(const Vec& q, const Vec& p) const {
  if (has(kFirstOrderOnly)) return std::numeric_limits<double>::quiet_NaN();
  if (kind() == ProblemKind::kLagrangian) return general_system(*this).hamiltonian(q, p);
  return kinetic(p) + potential(q);
}

void Problem::pack_first_order(const State& state, double* y) const {
  const int n = dof();
  Eigen::Map<Vec>(y, n) = state.q;
  if (!has(kFirstOrderOnly)) Eigen::Map<Vec>(y + n, n) = state.p;
}

void Problem::unpack_first_order(const double* y, State& state) const {
  const int n = dof();
  state.q = Eigen::Map<const Vec>(y, n);
  if (has(kFirstOrderOnly)) {
    state.p.resize(0);
  } else {
    state.p = Eigen::Map<const Vec>(y + n, n);
  }
}

double Problem::end_reference_time() const { missing(*this, "end reference"); }
State Problem::end_reference() const { missing(*this, "end reference"); }

void Problem::first_order_rhs(double t, const Vec& y, Vec& ydot) const {
  if (const FirstOrderSystem* system = as_first_order()) {
    system->rhs(t, y, ydot);
    return;
  }
  const int n = dof();
  ydot.resize(2 * n);
  if (kind() == ProblemKind::kLagrangian) {
    // Hamilton's equations of the general L: q̇ = v(q, p), ṗ = L_q(q, v) (docs/MECHANICS_GENERAL.md
    // §1; the Euler–Lagrange equation d/dt L_v = L_q with p = L_v, so one Cholesky solve per
    // evaluation, the same as M(q)v̇ = L_q − L_vq v would need).
    const LagrangianSystem& system = general_system(*this);
    const Vec q = y.head(n);
    const Vec v = system.velocity(q, y.tail(n));
    Vec L_q;
    system.lagrangian_q(q, v, L_q);
    ydot.head(n) = v;
    ydot.tail(n) = L_q;
    return;
  }
  // H(q, p, t): its own halves at t, not M⁻¹p and −∇V(q), which are H at the initial time only.
  if (const auto* hamiltonian = as<TimeDependentHamiltonian>()) {
    Vec qdot, pdot;
    hamiltonian->velocity(y.tail(n), t, qdot);
    hamiltonian->momentum_rate(y.head(n), y.tail(n), t, pdot);
    ydot.head(n) = qdot;
    ydot.tail(n) = pdot;
    return;
  }
  const Vec v = inverse_mass().cwiseProduct(y.tail(n));
  Vec g;
  gradient(y.head(n), g);
  ydot.head(n) = v;
  ydot.tail(n) = -g;
  if (const NonConservativeForce* forced = as_forced()) {
    Vec f;
    forced->force(y.head(n), v, t, f);
    ydot.tail(n) += f;
  }
}

void Problem::first_order_jacobian(double t, const Vec& y, SparseMatrix& J) const {
  if (const FirstOrderSystem* system = as_first_order()) {
    system->rhs_jacobian(t, y, J);
    return;
  }
  const int n = dof();
  if (kind() == ProblemKind::kLagrangian) {
    DenseMatrix dense;
    general_system(*this).hamiltonian_vector_field_jacobian(y.head(n), y.tail(n), dense);
    // Every entry, zeros included: a sparse solver (CVODE's KLU) keeps one pattern per run.
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(static_cast<size_t>(4 * n * n));
    for (int j = 0; j < 2 * n; ++j) {
      for (int i = 0; i < 2 * n; ++i) entries.emplace_back(i, j, dense(i, j));
    }
    J.resize(2 * n, 2 * n);
    J.setFromTriplets(entries.begin(), entries.end());
    return;
  }
  const Vec q = y.head(n);
  const Vec v = inverse_mass().cwiseProduct(y.tail(n));
  SparseMatrix H;
  hessian(q, H);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, n + i, inverse_mass()[i]);
  for (int k = 0; k < H.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(H, k); it; ++it) {
      triplets.emplace_back(n + it.row(), it.col(), -it.value());
    }
  }
  if (const NonConservativeForce* forced = as_forced()) {
    // ∂F/∂p = −C M⁻¹ from the analytic damping matrix; ∂F/∂q by central differences, because
    // forces (damping, driving) rarely provide it and it only shapes the Newton matrix.
    if (forced->has_force_jacobian()) {
      SparseMatrix C;
      forced->force_jacobian_v(q, v, t, C);
      for (int k = 0; k < C.outerSize(); ++k) {
        for (SparseMatrix::InnerIterator it(C, k); it; ++it) {
          triplets.emplace_back(n + it.row(), n + it.col(), -it.value() * inverse_mass()[it.col()]);
        }
      }
    }
    Vec f_plus, f_minus;
    Vec q_shift = q;
    // Steps relative to the size of q (1 only when q = 0), so tiny and huge states are
    // differenced alike.
    const double q_size = n > 0 ? q.cwiseAbs().maxCoeff() : 0.0;
    for (int j = 0; j < n; ++j) {
      const double size = std::max(std::abs(q[j]), q_size);
      const double delta = 1e-7 * (size > 0.0 && std::isfinite(size) ? size : 1.0);
      q_shift[j] = q[j] + delta;
      forced->force(q_shift, v, t, f_plus);
      q_shift[j] = q[j] - delta;
      forced->force(q_shift, v, t, f_minus);
      q_shift[j] = q[j];
      for (int i = 0; i < n; ++i) {
        const double d = (f_plus[i] - f_minus[i]) / (2 * delta);
        if (d != 0.0) triplets.emplace_back(n + i, j, d);
      }
    }
  }
  J.resize(2 * n, 2 * n);
  J.setFromTriplets(triplets.begin(), triplets.end());
}

}  // namespace geomint
