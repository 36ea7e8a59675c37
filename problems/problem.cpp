// Problem base-class defaults, the first-order view for ODE solvers, and the problem registry.
#include "problems/problem.hpp"

#include <fmt/format.h>

namespace geomint {

#define GEOMINT_PROBLEM(name, factory, variants, summary) std::unique_ptr<Problem> factory(Params&);
#include "problems/registry.def"
#undef GEOMINT_PROBLEM

const std::vector<ProblemEntry>& problem_registry() {
  static const std::vector<ProblemEntry> entries = {
#define GEOMINT_PROBLEM(name, factory, variants, summary) \
  {#name, summary, &factory, split_variants(variants)},
#include "problems/registry.def"
#undef GEOMINT_PROBLEM
  };
  return entries;
}

std::vector<std::string> problem_test_specs() {
  std::vector<std::string> specs;
  for (const auto& entry : problem_registry()) {
    specs.push_back(entry.name);
    for (const auto& variant : entry.variants) specs.push_back(entry.name + ":" + variant);
  }
  return specs;
}

std::unique_ptr<Problem> make_problem(const std::string& spec_text) {
  const Spec spec = Spec::parse(spec_text);
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
    return problem;
  }
  throw InputError(
      fmt::format("unknown problem '{}' (valid: {})", spec.name, fmt::join(names, ", ")));
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
  };
  std::vector<std::string> out;
  for (const auto& [bit, label] : kNames) {
    if (capabilities & bit) out.emplace_back(label);
  }
  return out;
}

namespace {
[[noreturn]] void missing(const Problem& problem, const char* what) {
  throw std::logic_error(fmt::format("problem '{}' has no {}", problem.name(), what));
}
}  // namespace

void Problem::hessian(const Vec&, SparseMatrix&) const { missing(*this, "hessian"); }
void Problem::force(const Vec&, const Vec&, double, Vec&) const { missing(*this, "force"); }
void Problem::force_jacobian_v(const Vec&, const Vec&, double, SparseMatrix&) const {
  missing(*this, "force Jacobian");
}
State Problem::exact(double) const { missing(*this, "exact solution"); }
Vec Problem::linear_momentum(const Vec&, const Vec&) const { missing(*this, "linear momentum"); }
Vec Problem::angular_momentum(const Vec&, const Vec&) const { missing(*this, "angular momentum"); }
double Problem::period() const { missing(*this, "period"); }
double Problem::omega_max(const Vec&) const { missing(*this, "omega_max"); }

void Problem::set_mass(const Vec& mass) {
  mass_ = mass;
  inverse_mass_ = mass.cwiseInverse();
}

double Problem::kinetic(const Vec& p) const { return 0.5 * p.dot(inverse_mass_.cwiseProduct(p)); }

double Problem::energy(const Vec& q, const Vec& p) const { return kinetic(p) + potential(q); }

void Problem::first_order_rhs(double t, const Vec& y, Vec& ydot) const {
  const int n = dof();
  ydot.resize(2 * n);
  const Vec v = inverse_mass_.cwiseProduct(y.tail(n));
  Vec g;
  gradient(y.head(n), g);
  ydot.head(n) = v;
  ydot.tail(n) = -g;
  if (has(kForce)) {
    Vec f;
    force(y.head(n), v, t, f);
    ydot.tail(n) += f;
  }
}

void Problem::first_order_jacobian(double t, const Vec& y, SparseMatrix& J) const {
  const int n = dof();
  const Vec q = y.head(n);
  const Vec v = inverse_mass_.cwiseProduct(y.tail(n));
  SparseMatrix H;
  hessian(q, H);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, n + i, inverse_mass_[i]);
  for (int k = 0; k < H.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(H, k); it; ++it) {
      triplets.emplace_back(n + it.row(), it.col(), -it.value());
    }
  }
  if (has(kForce)) {
    // ∂F/∂p = −C M⁻¹ from the analytic damping matrix; ∂F/∂q by central differences, because
    // forces (damping, driving) rarely provide it and it only shapes the Newton matrix.
    if (has(kForceJacobian)) {
      SparseMatrix C;
      force_jacobian_v(q, v, t, C);
      for (int k = 0; k < C.outerSize(); ++k) {
        for (SparseMatrix::InnerIterator it(C, k); it; ++it) {
          triplets.emplace_back(n + it.row(), n + it.col(), -it.value() * inverse_mass_[it.col()]);
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
      force(q_shift, v, t, f_plus);
      q_shift[j] = q[j] - delta;
      force(q_shift, v, t, f_minus);
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
