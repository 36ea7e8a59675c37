// The Integrator interface (docs/DESIGN.md §2): a one-step map on State = (t, q, p) with declared
// order and properties (flags) that the test suite checks, work counters, and failure statuses.
// Adaptive library solvers implement advance_to() instead of fixed steps.
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "problems/force.hpp"
#include "problems/problem.hpp"

namespace geomint {

enum MethodFlag : unsigned {
  kExplicit = 1u << 0,
  kImplicit = 1u << 1,
  kSymplectic = 1u << 2,       // canonical symplectic one-step map
  kSymmetric = 1u << 3,        // Φ_{−h} ∘ Φ_h = id
  kVariational = 1u << 4,      // derived from a discrete Lagrangian: discrete Noether holds
  kAdaptive = 1u << 5,         // error-controlled; use advance_to()
  kConstrained = 1u << 6,      // handles holonomic constraints (Problem kConstraints)
  kNeedsHessian = 1u << 7,     // needs Problem::hessian
  kConstraintsOnly = 1u << 8,  // only for problems with constraints (rattle, penalty, ida:index)
  kRheonomic = 1u << 9,        // also time-dependent constraints (kTimeDependentConstraints)
  // Runs a generic first-order system y' = f(t, y) (Problem::first_order_rhs/_jacobian), so
  // also the kFirstOrderOnly problems (van der Pol, Robertson); the others need (q, p, M, ∇V).
  kFirstOrderCapable = 1u << 10,
  // Integrates separable conservative systems only (Boost.Odeint's symplectic steppers): not run
  // on problems with a force F(q, v, t) (kForce), and applicable() says so.
  kConservativeOnly = 1u << 11,
  // Runs the general Lagrangian kind (non-separable problems, problems/lagrangian.hpp); without
  // it a method assumes ½vᵀMv − V with a constant M, and applicable() refuses it there.
  kGeneralLagrangian = 1u << 12,
  // Runs on free rigid bodies only (the Lie–Poisson splitting): applicable() admits it exactly
  // where problem.as<FreeRigidBodyStructure>() (problems/structures/free_rigid_body.hpp) finds
  // the structure it reads.
  kFreeRigidBodyOnly = 1u << 13,
  // Keeps the energy H(q, p) of a conservative problem to round-off and solver tolerance by
  // construction (avf for polynomial V, projection): a contrast to symplecticity, not a kind of it.
  kEnergyPreserving = 1u << 14,
  // Runs on charged particles only (the Boris pusher): applicable() admits it exactly where
  // problem.as<ChargedParticleStructure>() (problems/structures/charged_particle.hpp) finds m, q,
  // E, B and A.
  kChargedParticleOnly = 1u << 16,
};
std::vector<std::string> flag_names(unsigned flags);

struct MethodInfo {
  std::string name;  // registry name
  int order = 0;     // classical order of accuracy
  unsigned flags = 0;
  std::string reference;  // where the scheme is defined
};

// Who implements a method (docs/DESIGN.md §2, "Needs and provider"): this suite, a wrapped
// library (named: SUNDIALS, GSL, Boost.Odeint), an engine, or a user's run-time registration
// (register_method). Declared per registry entry (integrators/registry.def); reports and
// work-precision fronts ("best geomint method against best library solver") read it, never the
// method's name.
struct MethodProvider {
  enum class Kind { kGeomint, kLibrary, kEngine, kUser };
  Kind kind = Kind::kGeomint;
  std::string library;  // kLibrary (and kEngine): its name
  static MethodProvider geomint() { return {}; }
  static MethodProvider library_named(std::string name) {
    return {Kind::kLibrary, std::move(name)};
  }
  static MethodProvider user() { return {Kind::kUser, ""}; }
  // "geomint", "library:SUNDIALS", "engine:NAME", "user": the `provider` column of `geomint
  // list methods` and docs/METHODS.md, which scripts/work_precision_table.sh reads.
  std::string label() const;
  // Written out: odeint.cpp is compiled as C++17 (Boost.Odeint), where it cannot be defaulted.
  bool operator==(const MethodProvider& other) const {
    return kind == other.kind && library == other.library;
  }
};

// What a method needs of a problem (docs/DESIGN.md §2): the problem kinds it runs, the structure
// it reads, and what it assumes of constraints and forces. Derived in one place, method_needs(),
// from the flags the method declares (kFirstOrderCapable, kGeneralLagrangian, kFreeRigidBodyOnly,
// kChargedParticleOnly, kConstrained, kRheonomic, kConstraintsOnly, kConservativeOnly,
// kNeedsHessian), so that applicable() decides from requirements and never from method names.
struct MethodNeeds {
  // The ProblemKind bits the method runs: every method runs kSeparable problems (a
  // structure-only method is admitted by its structure first), kFirstOrder with
  // kFirstOrderCapable, kLagrangian with kGeneralLagrangian.
  unsigned kinds = static_cast<unsigned>(ProblemKind::kSeparable);
  // The key of a structure interface the method reads and cannot run without
  // (problems/structures/, Problem::as<Structure>()), nullptr for none; where the problem offers
  // it the method runs, whatever its kind.
  const StructureKey* structure = nullptr;
  bool handles_constraints = false;  // kConstrained
  bool handles_rheonomic = false;    // kRheonomic
  bool needs_constraints = false;    // kConstraintsOnly
  bool needs_conservative = false;   // kConservativeOnly: no force F(q, v, t)
  bool needs_hessian = false;        // kNeedsHessian (a kLagrangian problem always has one)
  bool runs(ProblemKind kind) const { return (kinds & static_cast<unsigned>(kind)) != 0; }
};
MethodNeeds method_needs(const MethodInfo& info);

// The method's family for work-precision fronts and the `family` column: adaptive_library
// (SUNDIALS, GSL, Boost.Odeint error-controlled solvers), adaptive_geomint (this suite's own
// error-controlled ones), explicit_symplectic, explicit_rk (explicit, not symplectic: RK4,
// Euler, the penalty wrapper), implicit_variational (implicit and variational or symplectic),
// implicit_other (implicit, neither: backward Euler, Newmark, HHT, generalized-α). Derived from the
// flags alone, plus the provider for adaptive methods (a library's is adaptive_library, any other
// adaptive_geomint); a method with neither kExplicit nor kImplicit is a defect (std::logic_error),
// so a new flag combination cannot silently leave a method unlabelled.
std::string method_family(const MethodInfo& info, const MethodProvider& provider);
// Every value method_family() returns, in the order figures list them.
const std::vector<std::string>& method_families();

// Result of one step; a failed step leaves the state unspecified and ends the run. [[nodiscard]]:
// a caller that drops a status turns a failed run into an `ok` row (a step loop that ignored its
// body's status once reported position Verlet's unconverged force kick as success), so dropping
// one is a compiler warning; a caller that really means it says so with a cast to void.
struct [[nodiscard]] StepStatus {
  bool ok = true;
  std::string reason;   // short CSV code: "nan", "newton_max_iter", "cvode_flag_-4", ...
  std::string message;  // human-readable detail
  static StepStatus success() { return {}; }
  static StepStatus failure(std::string reason, std::string message) {
    return {false, std::move(reason), std::move(message)};
  }
};

// The linear theory's largest stable step on the undamped harmonic oscillator q̈ = −ω²q
// (docs/METHOD.md §7; GNI §I.5, §XIII), as a bound on h·ω: +inf when every h is stable, 0 when
// none is, NaN when there is no prediction — then `reason` says why not. harness/stability.cpp
// reports it next to the measured limit.
struct StabilityPrediction {
  double homega_limit = std::numeric_limits<double>::quiet_NaN();
  std::string reason;  // why there is no prediction (homega_limit NaN)
  static StabilityPrediction limit(double homega) { return {homega, ""}; }
  static StabilityPrediction unconditional() {
    return {std::numeric_limits<double>::infinity(), ""};
  }
  static StabilityPrediction none(std::string why) {
    return {std::numeric_limits<double>::quiet_NaN(), std::move(why)};
  }
  bool predicted() const { return !std::isnan(homega_limit); }
};

// The α-rule family (hp:alpha, del:rule=alpha and symmetric_alpha, and del's left, right,
// trapezoid and midpoint rules as α ∈ {0, 1, 0, ½}): Newmark with γ = ½, β = α(1 − α) on linear
// forces (docs/METHOD.md §1), and ¼ − α(1 − α) = (½ − α)², so Newmark's bound gives hω < 1/|½ − α|.
StabilityPrediction alpha_rule_stability(double alpha);

// The fixed-step grid of a run (harness/run.cpp): t_k = t0 + k·dt for k < n and t_n = t0 + span
// exactly, so the last step is shortened only when dt does not divide span and t carries no
// accumulated round-off. Step k advances by h = t_k − t_{k−1} as computed from the state's t.
struct StepGrid {
  double t0 = 0;
  double dt = 0;
  double span = 0;
  long n = 0;
  double time(long k) const { return k == n ? t0 + span : t0 + static_cast<double>(k) * dt; }
};

// Sees the state after step k (state.t = t_k) and returns false to stop the run there. A
// function pointer and a context, so it costs no allocation; default-constructed = no visitor
// (the harness's timing pass), which lets explicit methods keep their state in registers.
class StepVisitor {
 public:
  StepVisitor() = default;
  template <class Callable>
  explicit StepVisitor(Callable& callable)
      : context_(&callable), call_([](void* context, const State& state, long k) {
          return (*static_cast<Callable*>(context))(state, k);
        }) {}
  explicit operator bool() const { return call_ != nullptr; }
  bool operator()(const State& state, long k) const { return call_(context_, state, k); }

 private:
  void* context_ = nullptr;
  bool (*call_)(void*, const State&, long) = nullptr;
};

// What Integrator::advance did: `steps` steps passed the integrator and the visitor; `status` is
// the integrator's failure in step steps + 1 (ok when every step ran or the visitor stopped).
struct [[nodiscard]] AdvanceOutcome {
  StepStatus status;
  long steps = 0;
};

// The multiplier impulses of a constrained step of length h (docs/METHOD.md §3): `start` acts
// along G(q_k)ᵀ (RATTLE's (h/2)λ, the KKT step's Λ) and `end` along G(q_{k+1})ᵀ (the velocity
// projection's ν), so p_{k+1} = p_k + (unconstrained impulses) − G(q_k)ᵀstart − G(q_{k+1})ᵀend.
struct ConstraintImpulses {
  Vec start, end;
  double h = 0.0;
  // (start + end)/h, the step's mean constraint force: the discrete multiplier the order study
  // fits against λ(t_k + h/2) (docs/METHOD.md §3, "Discrete multiplier").
  Vec mean_multiplier() const { return (start + end) / h; }
};

struct Counters {
  long steps = 0;
  long force_evals = 0;   // gradient (and force) evaluations
  long energy_evals = 0;  // potential evaluations (line searches)
  long hessian_evals = 0;
  long newton_iters = 0;
  long linear_solves = 0;
  long factorizations = 0;  // numeric factorisations of Newton matrices (NewtonResult)
  long rejected = 0;        // rejected steps (adaptive solvers)
};

class Integrator;
// Makes a fresh integrator of one parsed method spec (integrator_maker, below).
using IntegratorMaker = std::function<std::unique_ptr<Integrator>()>;

class Integrator {
 public:
  virtual ~Integrator() = default;

  virtual MethodInfo info() const = 0;
  // Canonical spec ("newmark:beta=0.25,gamma=0.5"), set by the registry.
  const std::string& spec() const { return spec_; }
  // Who implements it: its registry entry's provider, set by the registry (geomint for an
  // integrator built without it).
  const MethodProvider& provider() const { return provider_; }

  // Prepares for a run from `state` with nominal step h (h may be negative for reversibility
  // checks). Resets the counters. Methods with internal variables initialise them here.
  virtual void reset(const Problem& problem, const State& state, double h);
  // Advances state by h (fixed-step methods). Must not throw on numerical trouble: returns a
  // failed status instead. Checks for non-finite results are done by the harness.
  virtual StepStatus step(const Problem& problem, State& state, double h) = 0;
  // Runs the fixed-step grid from state (at grid.t0) to grid.time(grid.n), calling `visit` after
  // every step, with the same arithmetic, counters and final state as step() once per grid step
  // (integrators/integrator.cpp, the default). Explicit methods override it to dispatch once
  // per run to a loop without per-step status objects, cache checks or allocation.
  virtual AdvanceOutcome advance(const Problem& problem, State& state, const StepGrid& grid,
                                 StepVisitor visit);
  // Adaptive methods (flag kAdaptive): take one internal, error-controlled step without passing
  // t_stop, so observers see the solver's own step points (never interpolated output). The
  // harness calls it until state.t == t_stop.
  virtual StepStatus adaptive_step(const Problem& problem, State& state, double t_stop);

  // Every method says what the linear theory predicts for its stable step (with its own
  // parameters), or why it predicts nothing; the default covers adaptive methods only, so a
  // fixed-step method without an override fails the registry test in harness/stability_test.cpp.
  virtual StabilityPrediction predicted_linear_stability() const;

  // Why this method cannot run on any problem as configured ("" when it can): the bare `exec`
  // entry, which has no command to run. applicable() checks it first.
  virtual std::string refusal() const { return ""; }

  // The linearised step (docs/USAGE.md "Optional structure metrics"; integrators/tangent.hpp):
  // whether step_tangent() gives the exact DΦ of this method on `problem`. The default says no;
  // methods that implement it say yes on unforced, unconstrained problems with a Hessian
  // (tangent_applies()).
  virtual bool has_step_tangent(const Problem& problem) const;
  // One step exactly as step() from a reset at `state` (a method carrying a variable of its own,
  // HHT's acceleration, starts it consistently as reset() does), and `tangent` = DΦ =
  // ∂(q⁺, p⁺)/∂(q, p) at the incoming state, 2n×2n with (q, p) ordered as (q₁…qₙ, p₁…pₙ), from
  // the Hessian: explicit methods propagate tangent vectors through their stages, implicit ones
  // apply the implicit function theorem to their converged step equations. Only where
  // has_step_tangent(problem); the default throws std::logic_error.
  virtual StepStatus step_tangent(const Problem& problem, State& state, double h,
                                  Eigen::MatrixXd& tangent);

  const Counters& counters() const { return counters_; }

  // The multiplier impulses of the last step, for methods that solve for them (rattle, the
  // constrained hp/del step); empty otherwise (no step since reset(), unconstrained problem,
  // compositions, adaptive solvers).
  const std::optional<ConstraintImpulses>& last_constraint_impulses() const {
    return constraint_impulses_;
  }

 protected:
  // Evaluation helpers that keep the counters honest.
  void eval_gradient(const Problem& problem, const Vec& q, Vec& g);
  double eval_potential(const Problem& problem, const Vec& q);
  // gradient and, where the problem computes it in the same pass
  // (Problem::potential_with_gradient), the potential: whether V was set. Counts a force evaluation
  // only; the caller counts the energy evaluation when it uses V (so the counters record what the
  // method asked for).
  bool eval_gradient_with_potential(const Problem& problem, const Vec& q, Vec& g, double& V);
  void eval_hessian(const Problem& problem, const Vec& q, SparseMatrix& H);
  void eval_force(const Problem& problem, const Vec& q, const Vec& v, double t, Vec& f);
  // −∇V(q) + F(q, v, t): the total generalized force.
  void eval_total_force(const Problem& problem, const Vec& q, const Vec& v, double t, Vec& f);
  // The kick of an explicit method whose force F(q, v, t) must be taken at the velocity the kick
  // produces (Störmer–Verlet's last half-kick, position Verlet's kick at the mean velocity):
  // solves v = M⁻¹(p_base + weight·F(q, v, t)) for v by fixed-point iteration from the
  // guess in `velocity`, leaving that v in `velocity` and F(q, v, t) in `force` (the caller forms
  // its momentum from them in its own order of operations). The iteration contracts by
  // weight·‖M⁻¹∂F/∂v‖ per pass, below 1 wherever the explicit method is stable for the damping
  // (h·c/m < 2); a force that does not depend on v settles at its second evaluation with the
  // same bits as the first; `force` is the one v was formed from, so the two are consistent to
  // the last bit. Taking F at the guess instead ("Verlet with forces") is only first
  // order for a velocity-dependent F. Returns a failure "force_kick_max_iter" when v has not
  // settled (change ≤ 16ε‖v‖) after kMaxForceKickIterations passes. Extra evaluations count as
  // force evaluations.
  StepStatus solve_force_kick(const Problem& problem, const Vec& q, double t, const Vec& p_base,
                              double weight, Vec& velocity, Vec& force);
  static constexpr int kMaxForceKickIterations = 100;

  Counters counters_;
  std::optional<ConstraintImpulses> constraint_impulses_;  // cleared by reset()

 private:
  Vec extra_force_;  // eval_total_force's F(q, v, t), kept to avoid an allocation per call
  Vec kick_velocity_, kick_change_;  // solve_force_kick's next iterate and its change
  friend std::unique_ptr<Integrator> make_integrator(const std::string& spec_text);
  friend IntegratorMaker integrator_maker(const std::string& spec_text);
  std::string spec_;
  MethodProvider provider_;
};

// The diagonal mass matrix as a sparse matrix for Newton Jacobians: `matrix` is rebuilt only when
// the problem's masses differ from `diagonal`, the masses it was last built from.
void update_sparse_mass_matrix(const Problem& problem, Vec& diagonal, SparseMatrix& matrix);

// Whether a method can run on a problem, and if not why (an InputError message). The one place
// the harness asks (harness/run.cpp, harness/stability.cpp): rules for new problem kinds
// (holonomic constraints, first-order-only problems) are added here.
struct Applicability {
  bool ok = true;
  std::string reason;
};
Applicability applicable(const Integrator& method, const Problem& problem);
// A method that runs only the problems it can build a model of (the physics-engine methods,
// engines/) derives from this too: applicable() asks it first and refuses with its reason (which
// names the problems that apply) when that is not empty.
class RunsListedProblems {
 public:
  virtual ~RunsListedProblems() = default;
  virtual std::string problem_refusal(const Problem& problem) const = 0;
};
// The registry test specs whose methods handle holonomic constraints (for messages and tests).
std::vector<std::string> constrained_methods();
// The registry test specs whose methods run first-order-only problems (kFirstOrderCapable).
std::vector<std::string> first_order_methods();

// CVODE's "too much accuracy" test (tolsf, CVODE user guide §2.1): unit roundoff times the
// weighted RMS norm of y with weights 1/(rtol|y_i| + atol). Above 1 the tolerances ask for less
// than round-off, and an error-controlled solver can only crawl at the smallest representable
// step. Computed in long double so that the weights of atol = 1e-300 do not overflow; components
// with rtol|y_i| + atol = 0 are skipped.
double roundoff_tolerance_ratio(const double* y, long n, double rtol, double atol);

// The failure an adaptive wrapper reports when that ratio exceeds 1 (status `reason`).
StepStatus too_much_accuracy(const std::string& reason, const std::string& method, double t,
                             double rtol, double atol, double ratio);

// One record of what a method is (its declared MethodInfo), who provides it (its registry entry's
// MethodProvider) and what it needs of a problem (method_needs of its flags): what reports,
// `geomint list` and applicable() read, none of it from the method's name.
struct MethodRecord {
  MethodInfo info;
  MethodProvider provider;
  MethodNeeds needs;
};
MethodRecord method_record(const Integrator& method);

// Registry (integrators/registry.def). Throws InputError for unknown names/keys/values.
std::unique_ptr<Integrator> make_integrator(const std::string& spec_text);
// The same check, once: a callable that makes fresh integrators of this spec from the parsed
// text and the registry entry found for it (repeated runs build from the parse, not the text).
IntegratorMaker integrator_maker(const std::string& spec_text);

// `max_iter` of an implicit base method (its Newton iterations per solve), read from the wrapping
// method's `params` and appended to `base_spec` (a name at its defaults); 0 leaves the base's own
// limit and keeps the canonical spec as it was. An explicit base has no iteration to limit: an
// InputError naming `method`. Shared by the wrappers that run a base method (composition, penalty).
std::string with_base_max_iter(Params& params, const std::string& base_spec,
                               const std::string& method);

struct IntegratorEntry {
  std::string name;
  std::string summary;
  std::unique_ptr<Integrator> (*factory)(Params&);
  std::vector<std::string> variants;  // extra parameter sets the test suite must also cover
  // false for register_method() entries, which docs/METHODS.md's table leaves out
  bool builtin = true;
  // Who implements it: registry.def says for the built-ins; register_method() sets kUser unless
  // the entry names a library or an engine.
  // (Braced, so an entry written {name, summary, factory, variants} leaves it out without a
  // missing-initializer warning.)
  MethodProvider provider{};
};
// The provider of the registry entry `name` (a spec's name); InputError for an unknown name.
const MethodProvider& method_provider(const std::string& name);
// The built-in entries (registry.def) followed by the register_method() ones, in call order.
const std::vector<IntegratorEntry>& integrator_registry();

// A method defined outside the tree (docs/VERIFY.md "Verify your own integrator",
// docs/ARCHITECTURE.md): appended to the registry that make_integrator, `geomint list`, the sweeps,
// applicable() and the registry-driven tests read. Call it before run_main (or through a static
// MethodRegistrar); not thread-safe. Throws InputError for a name that is not a plain spec name or
// is already registered (a built-in's name included). `builtin` is set to false.
void register_method(IntegratorEntry entry);
struct MethodRegistrar {
  explicit MethodRegistrar(IntegratorEntry entry) { register_method(std::move(entry)); }
};

// Default specs to exercise in registry-driven tests and `geomint list`: one per entry, plus
// extra configurations an entry declares worth testing (e.g. hp with both solvers). Entries whose
// bare spec refuses every problem (Integrator::refusal(): `exec` without a command) are left out.
std::vector<std::string> integrator_test_specs();

}  // namespace geomint
