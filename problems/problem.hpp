// The Problem interface (docs/DESIGN.md §2): a Lagrangian system L(q, v) = ½ vᵀMv − V(q) with a
// constant diagonal (lumped) mass matrix, exact solution and momentum maps, and the queries for
// what else a kind of system offers (a first-order ODE, a general Lagrangian, constraints, a
// non-conservative force). Problems declare capabilities; the harness runs only what applies.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "problems/constraints.hpp"
#include "problems/fixed_gradient.hpp"
#include "problems/spec.hpp"
#include "problems/structure.hpp"

namespace geomint {

using Vec = Eigen::VectorXd;
using SparseMatrix = Eigen::SparseMatrix<double>;

// Canonical state: configuration q and momentum p = M v at time t.
struct State {
  double t = 0.0;
  Vec q;
  Vec p;
};

// What a problem offers beyond the required pieces. Instance-level: a pendulum has an exact
// solution only when it librates, a spring network has angular momentum only when free.
enum Capability : unsigned {
  kHessian = 1u << 0,          // hessian(q, H)
  kForce = 1u << 1,            // as_forced(): a non-conservative force F(q, v, t) (derived)
  kExact = 1u << 2,            // exact(t)
  kLinearMomentum = 1u << 3,   // linear_momentum(q, p) is a conserved quantity
  kAngularMomentum = 1u << 4,  // angular_momentum(q, p) is a conserved quantity
  kPeriod = 1u << 5,           // period()
  kOmegaMax = 1u << 6,         // omega_max(q)
  // as_forced()->has_force_jacobian(): C = −∂F/∂v for implicit dissipative solves (derived)
  kForceJacobian = 1u << 7,
  // Holonomic constraints g(q) = 0 (PAPER.md §3) and rheonomic g(q, t) = 0 (car_axis): derived
  // from Problem::as_constrained() and HolonomicConstraints::time_dependent(), never declared
  // (set_capabilities refuses them), so a problem cannot claim one without the other.
  kConstraints = 1u << 8,
  kTimeDependentConstraints = 1u << 9,
  // A first-order ODE y' = f(t, y) that is no Lagrangian system (van der Pol, Robertson): y is
  // State::q, State::p is empty, its FirstOrderSystem (problems/first_order.hpp) defines it; V,
  // ∇V, M and H mean nothing (energy() is NaN). Only methods with the flag kFirstOrderCapable run
  // it (applicable()). Derived from Problem::as_first_order(), never declared.
  kFirstOrderOnly = 1u << 10,
  kEndReference = 1u << 11,  // end_reference(): a tabulated state at one time (IVP Test Set)
  // casimir(q, p): a Casimir of the problem's Poisson structure that the motion keeps whatever
  // the Hamiltonian (|Π|² of a free rigid body), for the casimir_err_max metric.
  kCasimir = 1u << 12,
};

// Capability names for `geomint list` and error messages.
std::vector<std::string> capability_names(unsigned capabilities);

// The interfaces that define a problem's kind, its constraints and its force
// (problems/first_order.hpp, problems/lagrangian.hpp, problems/force.hpp). Structures that only
// some methods and metrics read come through Problem::as<Structure>() (problems/structures/).
class FirstOrderSystem;
class LagrangianSystem;
class NonConservativeForce;

// The kind of system a problem is (docs/DESIGN.md §2): which interface defines its motion, and so
// which methods can run it (MethodInfo's kinds, integrators/integrator.hpp).
enum class ProblemKind : unsigned {
  // y' = f(t, y) and nothing more (van der Pol, Robertson): as_first_order(); y is State::q,
  // State::p is empty, and V, ∇V, M and H mean nothing (has(kFirstOrderOnly)).
  kFirstOrder = 1u << 0,
  // L = ½vᵀMv − V(q) with a constant diagonal M: mass(), potential(), gradient() and the fast
  // paths built on them (fixed_gradient()).
  kSeparable = 1u << 1,
  // The general L(q, v) = ½vᵀM(q)v + a(q)ᵀv − V(q) with its Hamiltonian view: as_lagrangian().
  kLagrangian = 1u << 2,
};
// Name of a kind for messages ("first_order", "separable", "lagrangian").
const char* kind_name(ProblemKind kind);

class Problem {
 public:
  virtual ~Problem() = default;

  // Canonical spec: name plus every parameter, keys sorted.
  const std::string& spec() const { return spec_; }
  // Registry name ("pendulum").
  const std::string& name() const { return name_; }
  // The declared capabilities plus the ones derived from the structure queries (kConstraints,
  // kTimeDependentConstraints from as_constrained(), kFirstOrderOnly from as_first_order(),
  // kForce and kForceJacobian from as_forced()).
  // has() asks only the one query a derived bit comes from.
  unsigned capabilities() const;
  bool has(Capability c) const {
    return (c & kDerivedCapabilities) != 0 ? has_derived(c) : (capabilities_ & c) != 0;
  }
  static constexpr unsigned kDerivedCapabilities =
      kConstraints | kTimeDependentConstraints | kFirstOrderOnly | kForce | kForceJacobian;

  // ---- The kind and the structures the problem offers, each by one query (nullptr: absent) ----
  // A class that offers one derives from its interface as well and returns `this`; the queries
  // replace dynamic_casts and are checked against them for every registered problem
  // (problems/problems_test.cpp, ProblemKinds).
  ProblemKind kind() const;
  // The first-order ODE y' = f(t, y) of a kFirstOrder problem (problems/first_order.hpp, whose
  // FirstOrderProblem base returns it); such a problem has no Lagrangian pieces at all.
  virtual const FirstOrderSystem* as_first_order() const { return nullptr; }
  // The general Lagrangian interface (problems/lagrangian.hpp) of a kLagrangian problem. Such a
  // problem has no constant mass (mass() throws; its constructor calls set_dof), p = M(q)v + a(q),
  // energy() is H(q, p) and first_order_rhs() Hamilton's equations.
  virtual const LagrangianSystem* as_lagrangian() const { return nullptr; }
  // A structure interface the problem offers (problems/structures/: FreeRigidBodyStructure,
  // AttitudeStructure, ChargedParticleStructure, ...), or nullptr: one generic query, so Problem
  // names no concrete structure. Structure is any class with a `static constexpr StructureKey
  // kStructureKey` (problems/structure.hpp).
  template <class Structure>
  const Structure* as() const {
    return static_cast<const Structure*>(structure(Structure::kStructureKey));
  }
  // The interface of `key` as a pointer to it (the Structure subobject), or nullptr. A problem
  // that offers structures overrides it with one offer<Structure>() line per structure and ends
  // with its base class's structure(key).
  virtual const void* structure(const StructureKey& key) const {
    (void)key;
    return nullptr;
  }
  // Holonomic constraints g(q) = 0 or g(q, t) = 0 (problems/constraints.hpp: what a constrained
  // problem implements). Callers take the pointer once per run or step, not per element.
  virtual const HolonomicConstraints* as_constrained() const { return nullptr; }
  // A non-conservative generalized force F(q, v, t) (damping, driving) added to −∇V
  // (problems/force.hpp: what a forced problem implements). Instance-level like the constraints:
  // a damped oscillator with ζ = 0 and no drive returns nullptr and conserves H.
  virtual const NonConservativeForce* as_forced() const { return nullptr; }

  int dof() const { return dof_; }
  virtual State initial_state() const = 0;
  // The coordinates that must stay > 0 for q to mean a state (a polar radius: at r < 0 the polar
  // Kepler force 1/r² pulls outward), as (index into q, name): an initial state read from a file
  // is refused unless each is > 0 (given_initial_state.cpp).
  struct PositiveCoordinate {
    int index;
    const char* name;
  };
  virtual std::vector<PositiveCoordinate> positive_coordinates() const { return {}; }
  // Diagonal of the (lumped) mass matrix M, all entries > 0. Only the kSeparable kind has one:
  // on a kLagrangian problem (M(q), use its LagrangianSystem) or a kFirstOrder one (no mass at
  // all) mass(), inverse_mass() and kinetic() throw std::logic_error naming problem and kind.
  const Vec& mass() const {
    if (!has_constant_mass_) no_constant_mass();
    return mass_;
  }
  const Vec& inverse_mass() const {
    if (!has_constant_mass_) no_constant_mass();
    return inverse_mass_;
  }

  virtual double potential(const Vec& q) const = 0;
  // g = ∇V(q); g is resized by the callee.
  virtual void gradient(const Vec& q, Vec& g) const = 0;
  // V = potential(q) and g = gradient(q, g), bit for bit, from one pass where the problem has one
  // (an element loop forming each element's strain once): true. False, with g and V untouched,
  // where it has none; the caller then calls the two. For callers that need V wherever they take
  // ∇V (the HP minimiser's line search, docs/PERF.md "Energy with the gradient").
  virtual bool potential_with_gradient(const Vec& /*q*/, Vec& /*g*/, double& /*V*/) const {
    return false;
  }
  // The same ∇V as an inlineable functor (problems/fixed_gradient.hpp) for problems with a few
  // dof, so explicit methods can run a statically typed step loop; std::monostate when not
  // offered. Must round exactly as gradient() does (both call the functor).
  virtual FixedGradient fixed_gradient() const { return {}; }
  // H = ∇²V(q), symmetric, compressed. Only when has(kHessian).
  virtual void hessian(const Vec& q, SparseMatrix& H) const;
  // Exact solution. Only when has(kExact).
  virtual State exact(double t) const;
  // Total linear momentum Σ p_i per spatial direction. Only when has(kLinearMomentum).
  virtual Vec linear_momentum(const Vec& q, const Vec& p) const;
  // Total angular momentum Σ q_i × p_i (1 component in 2D, 3 in 3D). Only when
  // has(kAngularMomentum).
  virtual Vec angular_momentum(const Vec& q, const Vec& p) const;
  // The Casimir (|Π|² of the rigid bodies, problems/rigid_body.hpp). Only when has(kCasimir).
  virtual double casimir(const Vec& q, const Vec& p) const;
  // Period of the exact motion. Only when has(kPeriod).
  virtual double period() const;
  // The scalar whose upward zero crossings the period_measured metric times
  // (harness/structure_metrics.cpp): one that crosses 0 upwards once per period of the motion.
  // Default q[0] (the pendulum angle, the harmonic and Kepler x with the focus at 0); a problem
  // whose q[0] does not oscillate about 0 (a drifting centre of mass) overrides it.
  virtual double period_observable(const Vec& q, const Vec& p) const;
  // Highest linearised frequency at q (for stability reports). Only when has(kOmegaMax).
  virtual double omega_max(const Vec& q) const;
  // Whether V is quadratic (∇²V = K constant, needs kHessian): the normal modes K v = ω²M v are
  // then the motion's, and a method's one-step map is linear, so its linearised step is the map
  // itself (the normal-mode metrics, harness/structure_metrics.hpp).
  virtual bool is_linear() const { return false; }

  // ---- Helpers of a constrained problem (has(kConstraints); they throw std::logic_error on one
  // without). Members of Problem rather than of HolonomicConstraints because each combines the
  // constraints with the problem's mass, ∇V and force. ----
  // The exact motion's multipliers through (q, p) at time t: the λ that keeps d²g/dt² = 0,
  // (G M⁻¹ Gᵀ) λ = G M⁻¹ (−∇V + F) + c(q, v) + a_t.
  Vec multipliers(double t, const Vec& q, const Vec& p) const;
  // ‖g(q)‖∞ and ‖G(q) M⁻¹p‖∞ (position- and velocity-level constraint residuals); the versions
  // with t evaluate g(q, t) and G(q, t)v + g_t, and are the ones that hold for rheonomic
  // constraints (the time-free ones throw std::logic_error on such a problem).
  double constraint_residual(const Vec& q) const;
  double constraint_velocity_residual(const Vec& q, const Vec& p) const;
  double constraint_residual(double t, const Vec& q) const;
  double constraint_velocity_residual(double t, const Vec& q, const Vec& p) const;
  // Throws InputError unless `state` is consistent to round-off relative to its own scale:
  // ‖g(q)‖∞ ≤ tol·‖G‖∞‖q‖∞ and ‖G v‖∞ ≤ tol·‖G‖∞‖v‖∞ (no absolute floor). `what` names the
  // state in the message ("initial state").
  void check_consistent(const State& state, const std::string& what, double tol = 1e-10) const;

  // Extra problem-specific quantities for time series (e.g. the FPU oscillatory energies).
  virtual std::vector<std::string> series_names() const { return {}; }
  virtual void series_values(const Vec& q, const Vec& p, std::vector<double>& values) const {
    (void)q, (void)p, values.clear();
  }

  // Total energy H = ½pᵀM⁻¹p + V(q) (the conserved Hamiltonian when there is no force); H(q, p)
  // of the LagrangianSystem on a kLagrangian problem, NaN on a kFirstOrder one.
  double energy(const Vec& q, const Vec& p) const;
  // ½pᵀM⁻¹p: kSeparable only (throws std::logic_error otherwise, like mass()).
  double kinetic(const Vec& p) const;

  // Suggested step and horizon for `geomint run` without --dt/--t-end.
  double default_dt() const { return default_dt_; }
  double default_t_end() const { return default_t_end_; }

  // First-order view y = (q, p), y' = (M⁻¹p, −∇V(q) + F(q, M⁻¹p, t)) for ODE solvers; on a
  // kFirstOrderOnly problem y = q and y' = rhs(t, y).
  void first_order_rhs(double t, const Vec& y, Vec& ydot) const;
  // Sparse Jacobian ∂y'/∂y of first_order_rhs (needs has_first_order_jacobian()). A force's
  // ∂F/∂q is differenced numerically; its ∂F/∂p = −C M⁻¹ comes from force_jacobian_v when
  // has(kForceJacobian) and is left out otherwise (the catalogue's forces without a Jacobian,
  // car_axis and parametric_oscillator, do not depend on v).
  void first_order_jacobian(double t, const Vec& y, SparseMatrix& J) const;
  // Whether first_order_jacobian is analytic: a Hessian, or a first-order problem's
  // FirstOrderSystem::rhs_jacobian.
  bool has_first_order_jacobian() const { return has(kHessian) || has(kFirstOrderOnly); }
  // Length of y: 2·dof, or dof on a kFirstOrderOnly problem.
  int first_order_size() const { return has(kFirstOrderOnly) ? dof() : 2 * dof(); }
  // y = (q, p) from a state, and back (p is left empty on a kFirstOrderOnly problem).
  void pack_first_order(const State& state, double* y) const;
  void unpack_first_order(const double* y, State& state) const;

  // kEndReference: a reference state at end_reference_time() (the IVP Test Set's tabulated
  // solution at its end time), for error_final and scd (harness/observers.cpp). On Problem, not
  // on FirstOrderSystem: the second-order nbody (preset=pleiades, the Test Set's PLEI) offers one
  // as well.
  virtual double end_reference_time() const;
  virtual State end_reference() const;

 protected:
  // `self` as its Structure subobject when `key` is Structure's key, else nullptr: the body of a
  // structure() override, `if (auto* s = offer<FreeRigidBodyStructure>(key, this)) return s;`.
  template <class Structure, class Self>
  static const void* offer(const StructureKey& key, const Self* self) {
    if (&key != &Structure::kStructureKey) return nullptr;
    return static_cast<const Structure*>(self);
  }
  // Called once by the constructor: set_mass for a kSeparable problem (it sets dof() as well),
  // set_dof for a kLagrangian or kFirstOrder one, which has no constant mass.
  void set_mass(const Vec& mass);
  void set_dof(int dof);
  // Throws std::logic_error for kDerivedCapabilities: a problem declares constraints by
  // as_constrained(), a first-order ODE by as_first_order() and a force by as_forced(), not by a
  // bit.
  void set_capabilities(unsigned capabilities);
  void set_defaults(double dt, double t_end) {
    default_dt_ = dt;
    default_t_end_ = t_end;
  }

 private:
  friend std::unique_ptr<Problem> make_problem(const std::string& spec_text);
  // has() of a bit in kDerivedCapabilities: asks the one query it comes from.
  bool has_derived(Capability c) const;
  // The std::logic_error of mass(), inverse_mass() and kinetic() without a constant mass.
  [[noreturn]] void no_constant_mass() const;
  std::string name_;
  std::string spec_;
  unsigned capabilities_ = 0;
  int dof_ = 0;
  bool has_constant_mass_ = false;  // set_mass was called (the kSeparable kind)
  Vec mass_;
  Vec inverse_mass_;
  double default_dt_ = 0.01;
  double default_t_end_ = 10.0;
};

// *problem.as_constrained(), for code that runs only on constrained problems (applicable() checked
// kConstraints); throws std::logic_error naming the problem when it has none.
const HolonomicConstraints& constraints_of(const Problem& problem);
// *problem.as_first_order(), the same for code that runs only on first-order problems
// (problems/first_order.hpp); throws std::logic_error naming the problem when it is none.
const FirstOrderSystem& first_order_system_of(const Problem& problem);
// *problem.as_forced(), for code that runs only on forced problems (checked has(kForce)); throws
// std::logic_error naming the problem when it has no force.
const NonConservativeForce& force_of(const Problem& problem);

// Spec key every problem accepts: `initial=FILE.csv` starts the problem from the state in the
// file (rows q,p or, under a header "q,v", q,v; one per dof) instead of its own, and drops its
// exact solution and period. A wrong row count is an InputError naming n.
inline constexpr const char* kInitialStateKey = "initial";

// Registry (problems/registry.def). Throws InputError for unknown names/keys/values.
std::unique_ptr<Problem> make_problem(const std::string& spec_text);

struct ProblemEntry {
  std::string name;
  std::string summary;
  std::unique_ptr<Problem> (*factory)(Params&);
  std::vector<std::string> variants;  // extra parameter sets for the registry-driven tests
  // false for register_problem() entries, which docs/PROBLEMS.md's table leaves out
  bool builtin = true;
};
// The built-in entries (registry.def) followed by the register_problem() ones, in call order.
const std::vector<ProblemEntry>& problem_registry();

// A problem defined outside the tree, as register_method() for methods (integrators/
// integrator.hpp): seen by make_problem, `geomint list`, the sweeps and the registry-driven tests.
// Throws InputError for a name that is not a plain spec name or is already registered.
void register_problem(ProblemEntry entry);
struct ProblemRegistrar {
  explicit ProblemRegistrar(ProblemEntry entry) { register_problem(std::move(entry)); }
};

// The specs the registry-driven tests exercise (problems/problems_test.cpp): each entry's
// defaults, then its variants from problems/registry.def.
std::vector<std::string> problem_test_specs();

}  // namespace geomint
