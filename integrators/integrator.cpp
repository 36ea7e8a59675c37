// Integrator base-class helpers (counted evaluations) and the method registry.
#include "integrators/integrator.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "integrators/general_step.hpp"
#include "integrators/newton.hpp"
#include "integrators/time_treatment.hpp"
#include "problems/mass_operator.hpp"
#include "problems/structures/charged_particle.hpp"
#include "problems/structures/free_rigid_body.hpp"
#include "problems/structures/time_dependent.hpp"

namespace geomint {

#define GEOMINT_METHOD(name, factory, provider, variants, summary) \
  std::unique_ptr<Integrator> factory(Params&);
#include "integrators/registry.def"
#undef GEOMINT_METHOD

namespace {
// A function-local static, so register_method() called from another translation unit's static
// initialiser (MethodRegistrar) finds the built-in entries already in place.
// The provider column of registry.def.
MethodProvider by_geomint() { return MethodProvider::geomint(); }
MethodProvider by_library(const char* name) { return MethodProvider::library_named(name); }
MethodProvider by_engine(const char* name) { return {MethodProvider::Kind::kEngine, name}; }
MethodProvider by_user() { return MethodProvider::user(); }

std::vector<IntegratorEntry>& mutable_integrator_registry() {
  static std::vector<IntegratorEntry> entries = {
#define GEOMINT_METHOD(name, factory, provider, variants, summary) \
  {#name, summary, &factory, split_variants(variants), true, provider},
#include "integrators/registry.def"
#undef GEOMINT_METHOD
  };
  return entries;
}
}  // namespace

const std::vector<IntegratorEntry>& integrator_registry() { return mutable_integrator_registry(); }

void register_method(IntegratorEntry entry) {
  auto& entries = mutable_integrator_registry();
  check_registration_name(entry.name, "method");
  if (entry.factory == nullptr) {
    throw InputError(fmt::format("register_method: method '{}' has no factory", entry.name));
  }
  for (const auto& existing : entries) {
    if (existing.name == entry.name) {
      throw InputError(fmt::format("register_method: a method named '{}' is already registered{}",
                                   entry.name, existing.builtin ? " (built-in)" : ""));
    }
  }
  entry.builtin = false;
  // A method registered at run time is the user's, unless the entry says it wraps a library or
  // an engine (the default provider, geomint, is the built-ins' alone).
  if (entry.provider.kind == MethodProvider::Kind::kGeomint)
    entry.provider = MethodProvider::user();
  entries.push_back(std::move(entry));
}

std::string MethodProvider::label() const {
  switch (kind) {
    case Kind::kGeomint:
      return "geomint";
    case Kind::kLibrary:
      return "library:" + library;
    case Kind::kEngine:
      return "engine:" + library;
    case Kind::kUser:
      return "user";
  }
  return "geomint";
}

namespace {
// The registry entry named by `spec`; InputError listing the valid names otherwise.
const IntegratorEntry& find_method(const Spec& spec) {
  std::vector<std::string> names;
  for (const auto& entry : integrator_registry()) {
    if (entry.name == spec.name) return entry;
    names.push_back(entry.name);
  }
  throw InputError(fmt::format("unknown method '{}'{} (valid: {})", spec.name,
                               did_you_mean(spec.name, names), fmt::join(names, ", ")));
}
}  // namespace

std::unique_ptr<Integrator> make_integrator(const std::string& spec_text) {
  notify_spec_parse(spec_text);
  const Spec spec = Spec::parse(spec_text);
  const IntegratorEntry& entry = find_method(spec);
  Params params(spec, fmt::format("method '{}'", spec.name));
  auto integrator = entry.factory(params);
  params.finish();
  integrator->spec_ = params.canonical();
  integrator->provider_ = entry.provider;
  return integrator;
}

const MethodProvider& method_provider(const std::string& name) {
  return find_method(Spec{name, {}}).provider;
}

IntegratorMaker integrator_maker(const std::string& spec_text) {
  // Building one integrator checks every key and value and gives the canonical spec; later
  // integrators reuse the parsed spec and the entry's factory.
  const std::string canonical = make_integrator(spec_text)->spec();
  const Spec spec = Spec::parse(spec_text);
  const IntegratorEntry& entry = find_method(spec);
  const auto factory = entry.factory;
  const MethodProvider provider = entry.provider;
  return [spec, factory, canonical, provider] {
    Params params(spec, fmt::format("method '{}'", spec.name));
    auto integrator = factory(params);
    integrator->spec_ = canonical;
    integrator->provider_ = provider;
    return integrator;
  };
}

std::vector<std::string> integrator_test_specs() {
  std::vector<std::string> specs;
  for (const auto& entry : integrator_registry()) {
    // An entry that runs nowhere without the user's own parameters (`exec` needs the user's
    // program) has no spec to test here; its own tests run it (tests/exec).
    Params params(Spec{entry.name, {}}, entry.name);
    if (!entry.factory(params)->refusal().empty()) continue;
    specs.push_back(entry.name);
    for (const auto& variant : entry.variants) specs.push_back(entry.name + ":" + variant);
  }
  return specs;
}

const std::vector<std::string>& method_families() {
  static const std::vector<std::string> families = {"explicit_symplectic",  "explicit_rk",
                                                    "implicit_variational", "implicit_other",
                                                    "adaptive_geomint",     "adaptive_library"};
  return families;
}

std::string method_family(const MethodInfo& info, const MethodProvider& provider) {
  // Error control first: an adaptive method's cost is set by its tolerance, not a step.
  if (info.flags & kAdaptive) {
    return provider.kind == MethodProvider::Kind::kLibrary ? "adaptive_library"
                                                           : "adaptive_geomint";
  }
  if (info.flags & kExplicit) {
    return (info.flags & kSymplectic) ? "explicit_symplectic" : "explicit_rk";
  }
  if (info.flags & kImplicit) {
    // Every implicit symplectic method here comes from a discrete Lagrangian (HP, DEL, Gauss,
    // Lobatto IIIA–IIIB, midpoint): one family, so no front is drawn for an empty class.
    return (info.flags & (kVariational | kSymplectic)) ? "implicit_variational" : "implicit_other";
  }
  throw std::logic_error(info.name +
                         ": neither kExplicit nor kImplicit nor kAdaptive, so no method family");
}

std::vector<std::string> flag_names(unsigned flags) {
  static const std::pair<MethodFlag, const char*> kNames[] = {
      {kExplicit, "explicit"},
      {kImplicit, "implicit"},
      {kSymplectic, "symplectic"},
      {kSymmetric, "symmetric"},
      {kVariational, "variational"},
      {kAdaptive, "adaptive"},
      {kConstrained, "constrained"},
      {kNeedsHessian, "needs_hessian"},
      {kConstraintsOnly, "constraints_only"},
      {kRheonomic, "rheonomic"},
      {kFirstOrderCapable, "first_order"},
      {kConservativeOnly, "conservative_only"},
      {kGeneralLagrangian, "general_lagrangian"},
      {kFreeRigidBodyOnly, "free_rigid_body_only"},
      {kEnergyPreserving, "energy_preserving"},
      {kChargedParticleOnly, "charged_particle_only"},
  };
  std::vector<std::string> out;
  for (const auto& [bit, label] : kNames) {
    if (flags & bit) out.emplace_back(label);
  }
  return out;
}

double roundoff_tolerance_ratio(const double* y, long n, double rtol, double atol) {
  long double sum = 0;
  for (long i = 0; i < n; ++i) {
    const long double tolerance = static_cast<long double>(rtol) * std::abs(y[i]) + atol;
    if (!(tolerance > 0)) continue;
    const long double scaled = y[i] / tolerance;
    sum += scaled * scaled;
  }
  const long double norm = n > 0 ? std::sqrt(sum / static_cast<long double>(n)) : 0.0L;
  return static_cast<double>(std::numeric_limits<double>::epsilon() / 2 * norm);
}

StepStatus too_much_accuracy(const std::string& reason, const std::string& method, double t,
                             double rtol, double atol, double ratio) {
  return StepStatus::failure(
      reason, fmt::format("{}: too much accuracy requested at t={:.6g}: rtol={:g}, atol={:g} are "
                          "below round-off (unit roundoff x weighted norm of y = {:g} > 1); "
                          "loosen the tolerances",
                          method, t, rtol, atol, ratio));
}

void Integrator::reset(const Problem&, const State&, double) {
  counters_ = Counters{};
  constraint_impulses_.reset();
}

AdvanceOutcome Integrator::advance(const Problem& problem, State& state, const StepGrid& grid,
                                   StepVisitor visit) {
  AdvanceOutcome outcome;
  for (long k = 1; k <= grid.n; ++k) {
    const double t_next = grid.time(k);
    outcome.status = step(problem, state, t_next - state.t);
    state.t = t_next;
    if (!outcome.status.ok || (visit && !visit(state, k))) return outcome;
    outcome.steps = k;
  }
  return outcome;
}

void update_sparse_mass_matrix(const Problem& problem, Vec& diagonal, SparseMatrix& matrix) {
  const Vec& mass = MassOperator(problem).constant_diagonal();
  if (matrix.rows() != problem.dof() || diagonal != mass) {
    diagonal = mass;
    matrix = SparseMatrix(mass.asDiagonal());
  }
}

namespace {
// The structure-only flags and the structure interface (problems/structures/) each one needs:
// applicable() asks the problem for that interface by its key and knows no structure by name.
const std::pair<MethodFlag, const StructureKey*> kStructureNeeds[] = {
    {kFreeRigidBodyOnly, &FreeRigidBodyStructure::kStructureKey},
    {kChargedParticleOnly, &ChargedParticleStructure::kStructureKey},
};
}  // namespace

MethodNeeds method_needs(const MethodInfo& info) {
  MethodNeeds needs;
  if (info.flags & kFirstOrderCapable)
    needs.kinds |= static_cast<unsigned>(ProblemKind::kFirstOrder);
  if (info.flags & kGeneralLagrangian)
    needs.kinds |= static_cast<unsigned>(ProblemKind::kLagrangian);
  for (const auto& [flag, key] : kStructureNeeds) {
    if (info.flags & flag) needs.structure = key;
  }
  needs.handles_constraints = (info.flags & kConstrained) != 0;
  needs.handles_rheonomic = (info.flags & kRheonomic) != 0;
  needs.needs_constraints = (info.flags & kConstraintsOnly) != 0;
  needs.needs_conservative = (info.flags & kConservativeOnly) != 0;
  needs.needs_hessian = (info.flags & kNeedsHessian) != 0;
  return needs;
}

MethodRecord method_record(const Integrator& method) {
  MethodRecord record{method.info(), method.provider(), {}};
  record.needs = method_needs(record.info);
  return record;
}

namespace {

bool offers(const Problem& problem, const StructureKey* structure) {
  return structure != nullptr && problem.structure(*structure) != nullptr;
}

std::string structure_refusal(const Integrator& method, const Problem& problem,
                              const StructureKey& structure) {
  return fmt::format("method '{}' integrates {} only ({}); problem '{}' is none", method.spec(),
                     structure.what, structure.offered_by, problem.name());
}

std::string lagrangian_kind_refusal(const Integrator& method, const Problem& problem) {
  const auto* explains = dynamic_cast<const ExplainsGeneralRefusal*>(&method);
  const std::string specific = explains ? explains->general_lagrangian_refusal() : "";
  if (!specific.empty()) {
    return fmt::format(
        "method '{}' does not run problem '{}', which is non-separable "
        "(a position-dependent mass M(q) or a gyroscopic term): {}; "
        "methods that apply: {}",
        method.spec(), problem.spec(), specific, fmt::join(general_lagrangian_methods(), ", "));
  }
  return fmt::format(
      "method '{}' assumes a separable Lagrangian ½vᵀMv − V(q) with a constant "
      "mass (its step uses M⁻¹p and ∇V); problem '{}' is non-separable (a "
      "position-dependent mass M(q) or a gyroscopic term); methods that apply: "
      "{}",
      method.spec(), problem.spec(), fmt::join(general_lagrangian_methods(), ", "));
}

}  // namespace

Applicability applicable(const Integrator& method, const Problem& problem) {
  if (std::string why = method.refusal(); !why.empty()) return {false, std::move(why)};
  const MethodNeeds needs = method_needs(method.info());
  // A free rigid body gives such a method all it reads (moments and the (Q, Π) view), be it the
  // first-order rigid_body_euler or the constrained rigid_body; a charged particle gives the
  // Boris pusher its m, q, E(x), B(x) and A(x).
  if (offers(problem, needs.structure)) return {};
  const ProblemKind kind = problem.kind();
  // A first-order system offers y' = f(t, y) only: a method that runs it needs nothing else.
  if (kind == ProblemKind::kFirstOrder) {
    if (needs.runs(kind)) return {};
    return {false,
            fmt::format("method '{}' integrates Lagrangian systems (q, p, M, grad V); "
                        "problem '{}' is a first-order ODE y' = f(t, y) only; methods "
                        "that apply: {}",
                        method.spec(), problem.name(), fmt::join(first_order_methods(), ", "))};
  }
  // A method that models only some problems (a physics engine) says which, and runs each of
  // those as a whole: it reads the problem's parameters, not its functions, so the checks below
  // (kinds, constraints) do not concern it (an engine's ball joint runs the constrained
  // spherical pendulum and rigid body).
  if (const auto* listed = dynamic_cast<const RunsListedProblems*>(&method)) {
    std::string refusal = listed->problem_refusal(problem);
    if (!refusal.empty()) return {false, std::move(refusal)};
    return {};
  }
  if (needs.structure != nullptr) {
    return {false, structure_refusal(method, problem, *needs.structure)};
  }
  // H(q, p, t): a method that reads only M⁻¹p and ∇V(q) would integrate H frozen at t = t₀.
  if (problem.as<TimeDependentHamiltonian>() != nullptr &&
      time_treatment(method) == TimeTreatment::kNone) {
    return {false,
            fmt::format("method '{}' does not treat time (its step reads M⁻¹p and ∇V(q), "
                        "never t); problem '{}' has a time-dependent Hamiltonian H(q, p, "
                        "t); methods that treat time: {}",
                        method.spec(), problem.name(), fmt::join(time_dependent_methods(), ", "))};
  }
  if (!needs.runs(kind)) return {false, lagrangian_kind_refusal(method, problem)};
  // On a non-separable problem the second derivatives come from its LagrangianSystem.
  if (needs.needs_hessian && !problem.has(kHessian) && kind != ProblemKind::kLagrangian) {
    return {false, fmt::format("method '{}' needs a Hessian, which problem '{}' does not have",
                               method.info().name, problem.name())};
  }
  if (problem.has(kConstraints) && !needs.handles_constraints) {
    return {false,
            fmt::format("method '{}' does not handle holonomic constraints, which problem "
                        "'{}' has; methods that do: {}",
                        method.spec(), problem.name(), fmt::join(constrained_methods(), ", "))};
  }
  // Constraints on the general kind (a mass M(q): andrews) need a constrained step built on the
  // problem's LagrangianSystem: every method flagged both constrained and general_lagrangian has
  // one (ida:index=2|3's residual p' = L_q + F − Gᵀλ; rattle, hp and del:rule=midpoint through
  // integrators/general_constrained_step.hpp; compositions over them), and the kind check above
  // has refused the others.
  if (problem.has(kTimeDependentConstraints) && !needs.handles_rheonomic) {
    return {false, fmt::format("method '{}' handles only time-free constraints; problem '{}' has "
                               "time-dependent ones (rattle, hp, del:rule=midpoint, compositions "
                               "over rattle or hp_midpoint, ida:index=2 or ida:index=3 solve it)",
                               method.spec(), problem.name())};
  }
  if (needs.needs_conservative && problem.has(kForce)) {
    // The flag says the step is the flow of a Hamiltonian with no term for a force; whether the
    // method also needs a separable H is a different requirement (the kinds, above):
    // generalized_leapfrog and tao run non-separable H but no forced problem.
    return {false, fmt::format("method '{}' integrates conservative systems only (its step "
                               "follows a Hamiltonian H(q, p) and has no term for a force); "
                               "problem '{}' has a non-conservative force F(q, v, t) (damping, "
                               "driving or a modulation); methods without the flag "
                               "conservative_only take it",
                               method.spec(), problem.name())};
  }
  if (needs.needs_constraints && !problem.has(kConstraints)) {
    return {false, fmt::format("method '{}' is for problems with holonomic constraints; problem "
                               "'{}' has none (use an unconstrained method)",
                               method.spec(), problem.name())};
  }
  return {};
}

std::vector<std::string> constrained_methods() {
  std::vector<std::string> specs;
  for (const auto& spec : integrator_test_specs()) {
    const unsigned flags = make_integrator(spec)->info().flags;
    if ((flags & kConstrained) && !(flags & kFreeRigidBodyOnly)) specs.push_back(spec);
  }
  if (specs.empty()) specs.push_back("(none registered yet)");
  return specs;
}

std::vector<std::string> first_order_methods() {
  std::vector<std::string> specs;
  for (const auto& spec : integrator_test_specs()) {
    const unsigned flags = make_integrator(spec)->info().flags;
    if ((flags & kFirstOrderCapable) && !(flags & kConstraintsOnly)) specs.push_back(spec);
  }
  return specs;
}

const char* time_treatment_name(TimeTreatment treatment) {
  switch (treatment) {
    case TimeTreatment::kNone:
      return "none";
    case TimeTreatment::kStageTimes:
      return "stage_times";
    case TimeTreatment::kExtendedPhaseSpace:
      return "extended_phase_space";
    case TimeTreatment::kFrozenPerStep:
      return "frozen_per_step";
  }
  return "none";
}

TimeTreatment time_treatment(const Integrator& method) {
  if (const auto* own = dynamic_cast<const TreatsTime*>(&method)) return own->time_treatment();
  // These see the problem only through first_order_rhs(t, y), which a time-dependent H answers
  // at the t each stage passes (Problem::first_order_rhs).
  const unsigned flags = method.info().flags;
  if ((flags & kFirstOrderCapable) && (flags & kGeneralLagrangian)) {
    return TimeTreatment::kStageTimes;
  }
  return TimeTreatment::kNone;
}

std::vector<std::string> time_dependent_methods() {
  std::vector<std::string> specs;
  for (const auto& spec : integrator_test_specs()) {
    if (time_treatment(*make_integrator(spec)) != TimeTreatment::kNone) specs.push_back(spec);
  }
  return specs;
}

std::vector<std::string> general_lagrangian_methods() {
  std::vector<std::string> specs;
  for (const auto& spec : integrator_test_specs()) {
    if (make_integrator(spec)->info().flags & kGeneralLagrangian) specs.push_back(spec);
  }
  if (specs.empty()) specs.push_back("(none registered yet)");
  return specs;
}

StabilityPrediction alpha_rule_stability(double alpha) {
  if (alpha == 0.5) return StabilityPrediction::unconditional();
  return StabilityPrediction::limit(1.0 / std::abs(0.5 - alpha));
}

StabilityPrediction Integrator::predicted_linear_stability() const {
  if (info().flags & kAdaptive) {
    return StabilityPrediction::none(
        "adaptive: error control chooses the step, so there is no fixed-step limit");
  }
  return StabilityPrediction::none("");
}

bool Integrator::has_step_tangent(const Problem&) const { return false; }

StepStatus Integrator::step_tangent(const Problem&, State&, double, Eigen::MatrixXd&) {
  throw std::logic_error(info().name + ": step_tangent is not implemented (has_step_tangent)");
}

StepStatus Integrator::adaptive_step(const Problem&, State&, double) {
  return StepStatus::failure("not_adaptive", "method has no adaptive_step; use step()");
}

void Integrator::eval_gradient(const Problem& problem, const Vec& q, Vec& g) {
  ++counters_.force_evals;
  problem.gradient(q, g);
}

bool Integrator::eval_gradient_with_potential(const Problem& problem, const Vec& q, Vec& g,
                                              double& V) {
  ++counters_.force_evals;
  if (problem.potential_with_gradient(q, g, V)) return true;
  problem.gradient(q, g);
  return false;
}

double Integrator::eval_potential(const Problem& problem, const Vec& q) {
  ++counters_.energy_evals;
  return problem.potential(q);
}

void Integrator::eval_hessian(const Problem& problem, const Vec& q, SparseMatrix& H) {
  ++counters_.hessian_evals;
  problem.hessian(q, H);
}

void Integrator::eval_force(const Problem& problem, const Vec& q, const Vec& v, double t, Vec& f) {
  force_of(problem).force(q, v, t, f);
}

StepStatus Integrator::solve_force_kick(const Problem& problem, const Vec& q, double t,
                                        const Vec& p_base, double weight, Vec& velocity,
                                        Vec& force) {
  const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
  eval_force(problem, q, velocity, t, force);
  double change = 0.0;
  for (int pass = 0; pass < kMaxForceKickIterations; ++pass) {
    kick_velocity_ = inverse_mass.cwiseProduct(p_base + weight * force);
    kick_change_ = kick_velocity_ - velocity;  // into a kept vector: advance() must not allocate
    change = robust_norm(kick_change_);
    velocity.swap(kick_velocity_);
    if (change <= kRoundoffFloor * robust_norm(velocity)) return StepStatus::success();
    if (!velocity.allFinite()) break;
    ++counters_.force_evals;
    eval_force(problem, q, velocity, t, force);
  }
  return StepStatus::failure(
      "force_kick_max_iter",
      fmt::format("the velocity of the force kick did not settle in {} fixed-point passes "
                  "(last change {:.3g} relative to |v| = {:.3g}): the step is beyond the explicit "
                  "method's stability for this damping (h·c/m ≥ 2)",
                  kMaxForceKickIterations, change, robust_norm(velocity)));
}

void Integrator::eval_total_force(const Problem& problem, const Vec& q, const Vec& v, double t,
                                  Vec& f) {
  eval_gradient(problem, q, f);
  f = -f;
  if (const NonConservativeForce* forced = problem.as_forced()) {
    forced->force(q, v, t, extra_force_);
    f += extra_force_;
  }
}

std::string with_base_max_iter(Params& params, const std::string& base_spec,
                               const std::string& method) {
  const long max_iter = params.integer(
      "max_iter", 0, "Newton iterations per solve of an implicit base (0: the base's own limit)", 0,
      10000);
  params.omit_default_from_canonical("max_iter");
  if (max_iter == 0) return base_spec;
  if (!(make_integrator(base_spec)->info().flags & kImplicit)) {
    throw InputError(
        fmt::format("{}: max_iter limits an implicit base's solves; base '{}' is "
                    "explicit",
                    method, base_spec));
  }
  return base_spec + (base_spec.find(':') == std::string::npos ? ":" : ",") +
         fmt::format("max_iter={}", max_iter);
}

}  // namespace geomint
