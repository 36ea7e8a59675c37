// Sparse Newton solver of the implicit methods (implicit Euler, Newmark, DEL, HP, Gauss...): damped
// Newton with Armijo backtracking (Nocedal & Wright, 2nd ed., §3.1, §11.1), solve() a loop over
// named phases (newton.cpp); the few-dof general-Lagrangian steps use dense_newton.hpp instead.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "problems/problem.hpp"

namespace geomint {

class Params;

// Which solver factorises (or iterates on) a symmetric Newton matrix (docs/METHODS.md "Scale").
// Non-symmetric Jacobians always go to SparseLU.
//  - kLdlt: Eigen SimplicialLDLT, AMD ordering (bit-identical to the results committed before the
//    choice existed); kLdltMetis: the same with METIS nested-dissection ordering.
//  - kCholmod: CHOLMOD supernodal LLᵀ (METIS ordering, dense supernodes through the BLAS).
//  - kCg, kCgIchol: preconditioned conjugate gradients (diagonal or incomplete-Cholesky
//    preconditioner), solved to a residual tied to the Newton threshold, so the Newton stopping
//    test — and with it every conservation result — is unchanged.
//  - kCgAmg: the same CG with one BoomerAMG V-cycle as preconditioner (integrators/boomer_amg.hpp),
//    its set-up reused across Newton iterations and steps
//    (LinearSolverOptions::amg_refresh_growth).
//  - kAuto: by the number of unknowns, from the measurements next to kAutoIterativeFrom.
enum class LinearSolverKind { kAuto, kLdlt, kLdltMetis, kCholmod, kCg, kCgIchol, kCgAmg };

// `auto` picks kLdlt below this many unknowns (every committed result, bit for bit) and kCg from
// it on. Measured (docs/METHODS.md "Scale", CPU s of a whole one-step run, 2-core machine under
// load 5–7):
//   /usr/bin/time -f "%U %S" build/geomint run --problem elastic_bar:nx=26,ny=8,nz=8
//     --method hp:linear_solver=cg --dt 0.022 --t-end 0.022 --timing-repeats 0
// (and ldlt, cholmod; nx=65,ny=16,nz=16 with --dt 0.011; bench/bench_linear_solvers.cpp).
// 960 tets (825 dof): all three 0.05 s; 9 984 tets (6 561 dof): ldlt 0.80, cholmod 0.44, cg 0.23;
// 99 840 tets (56 355 dof, h = 0.011): cholmod 10.3, cg 1.7 (ldlt: 343 s).
inline constexpr long kAutoIterativeFrom = 6000;

struct LinearSolverOptions {
  LinearSolverKind kind = LinearSolverKind::kAuto;
  // Modified Newton: keep the last factorisation while the iteration contracts the residual by at
  // least kModifiedNewtonContraction per iteration, across iterations and steps (a new Jacobian
  // is factorised as soon as it does not, and at once when a direction from the held one fails:
  // CG does not converge, no descent, no acceptable step). With the CG solvers the held Newton
  // matrix (and its preconditioner) is what CG iterates on, so the Hessian is not reassembled
  // (docs/PERF.md "Hessian reuse").
  bool modified_newton = false;
  // cg_amg keeps its multigrid set-up (built from an earlier matrix: a preconditioner need not be
  // of the current one) until a CG solve takes more than amg_refresh_growth × (the iterations per
  // decade of the first solve after that set-up) × its decades + kAmgRefreshSlack iterations, and
  // rebuilds it on the next Jacobian; a CG failure with an old set-up rebuilds it at once and
  // solves again. 0 rebuilds for every Jacobian.
  double amg_refresh_growth = 2.0;
};

// Iterations a reused AMG set-up may add to a small baseline before it counts as worn out (a
// baseline of 3 iterations rising to 7 is noise, not a worse preconditioner).
inline constexpr int kAmgRefreshSlack = 4;

// Largest ‖R_{k+1}‖/‖R_k‖ for which modified Newton keeps its factorisation.
inline constexpr double kModifiedNewtonContraction = 0.25;

// Reads the method options `linear_solver=` and `modified_newton=` (InputError naming the allowed
// values). Every method that solves with NewtonSolver calls it next to its tol/max_iter reads.
LinearSolverOptions read_linear_solver_option(Params& params);

// The solver a LinearSolverOptions::kind resolves to for a system of `unknowns` unknowns.
LinearSolverKind resolve_linear_solver(LinearSolverKind kind, long unknowns);
// "ldlt", "ldlt_metis", "cholmod", "cg", "cg_ichol", "cg_amg", "auto".
const char* linear_solver_name(LinearSolverKind kind);

// Smallest relative residual the stopping test asks for: R sums a few terms, each rounded to
// ε of its size, so ‖R‖ cannot reliably get below a small multiple of ε·residual_scale. The
// same factor bounds the relative Newton correction below which x counts as converged at
// round-off (NewtonResult::at_roundoff).
inline constexpr double kRoundoffFloor = 16 * 2.220446049250313e-16;

// The only absolute floor of the stopping tests: a residual (or correction) below the smallest
// normal double counts as zero. Below it, numbers lose relative precision (subnormals), so a
// relative test can no longer be met; it matters only for states smaller than ~1e-290 (a
// dissipative run decaying towards 0, say), which it lets end as converged steps.
inline constexpr double kSubnormalResidual = 2.2250738585072014e-308;  // DBL_MIN

// The minimiser's line search also accepts a step when E's change is lost in E's rounding but
// the slope along the step, R(x + αd)·d, says E decreased (Hager & Zhang, SIAM J. Optim. 16(1)
// 2005, "approximate Wolfe" conditions, §4): for a quadratic E, φ(α) − φ(0) = α(φ'(0) + φ'(α))/2,
// so Armijo φ(α) ≤ φ(0) + c₁αφ'(0) is exactly φ'(α) ≤ (2c₁ − 1)φ'(0), and φ' comes from R, whose
// rounding is that of the gradient's terms, not of the energy's. E may then rise by no more than
// this fraction of its size (Hager & Zhang's ε = 1e-6), which still rejects a step across a
// hill of E towards another stationary point. Measured (results/minimize_vs_newton/README.md
// "minimize_vs_newton", spinning free elastic bar at t = 2.29): E's rounding ~120ε·objective_scale,
// above the 16ε the value test allows, while a full Newton step cut ‖R‖ from 1.5e-6 to 7e-14.
inline constexpr double kApproximateArmijoSlack = 1e-6;

struct NewtonOptions {
  // Converged when ‖R(x)‖₂ ≤ max(tolerance, kRoundoffFloor) · residual_scale, where
  // residual_scale (passed to solve(), plus NewtonSystem::scale_after_first_residual) is the size
  // of the terms that R balances, e.g. ‖p_k‖ + h‖∇V‖ for a momentum residual. The test is
  // relative to the physics, with no absolute floor above the subnormals (kSubnormalResidual),
  // and its norms are robust_norm's, so a state of any size from 1e-250 to 1e+250 is solved to
  // the same relative accuracy as one of size 1 (scale-free); kRoundoffFloor keeps a tolerance
  // far below ε from asking for a residual below the rounding of its own terms.
  double tolerance = 1e-12;
  int max_iterations = 50;  // Newton updates (Jacobian factorisations) allowed per solve
  // Backtracking on the merit function (½‖R‖², or the system's objective when it has one).
  bool line_search = true;
  int max_backtracks = 30;  // halvings of the step before the line search gives up
  double armijo = 1e-4;     // sufficient-decrease constant c₁
  // Keep the symbolic factorisation (fill-reducing ordering, elimination tree) while the
  // Jacobian's sparsity pattern stays the same; only the numeric factorisation is redone.
  bool reuse_symbolic = true;
  // Store ‖R‖ after every iteration in NewtonResult::residual_history (tests, diagnostics).
  bool record_history = false;
  // After convergence, one more simplified-Newton correction with the last factorisation (no new
  // Jacobian, one back-substitution and one residual evaluation), kept only if it lowers ‖R‖.
  // Quadratic convergence makes it take ‖R‖ from just below the tolerance to its round-off floor,
  // which invariants that are exact only for the exact solve (angular momentum of a variational
  // integrator, docs/METHOD.md §4) need over 10⁵ steps; the tolerance alone allows a 1e-12 error a
  // step.
  bool polish = false;
  // Schedule of the SPD safeguard (NewtonSystem::spd_shift): μ = spd_shift_initial (or the last
  // successful μ of the solve / spd_shift_growth, if larger), ·spd_shift_growth, … at most
  // max_spd_shifts times per iteration.
  double spd_shift_initial = 1e-3;
  double spd_shift_growth = 10.0;
  int max_spd_shifts = 40;
  LinearSolverOptions linear;
};

// The `tol` and `max_iter` options of every implicit method, read once here so that each method
// accepts the same keys, defaults and ranges; `residual_scale` names what the relative tolerance
// is relative to (the method's residual_scale passed to NewtonSolver::solve), for the help text.
NewtonOptions read_newton_options(Params& params, const std::string& residual_scale);

// The nonlinear system R(x) = 0 to solve.
struct NewtonSystem {
  // R(x); must resize `residual`. Non-finite entries make the solve fail with reason "nan"
  // (or, inside a line search, shorten the step).
  std::function<void(const Vec& x, Vec& residual)> residual;
  // J = ∂R/∂x, compressed. It may be reused between calls with the same pattern.
  std::function<void(const Vec& x, SparseMatrix& jacobian)> jacobian;
  // Declares J symmetric: factorised with SimplicialLDLT (reads the lower triangle only),
  // otherwise with SparseLU.
  bool symmetric = false;
  // Optional scalar E(x) with ∇E = R (minimisation form, docs/METHOD.md §4). When present the line
  // search enforces Armijo decrease of E instead of ½‖R‖², so the iteration is a globalised
  // minimisation; a Newton direction that is not a descent direction of E (J not positive
  // definite) fails with reason "not_descent" unless the SPD safeguard below is enabled.
  std::function<double(const Vec& x)> objective;
  // Size of the terms the objective sums (e.g. |½xᵀMx| + |pᵀx| + |V|): E's round-off is about
  // ε·objective_scale even where E itself is near zero by cancellation. The line search treats
  // changes of E below that level as noise (see solve()). 0: use |E|.
  double objective_scale = 0.0;
  // Optional SPD safeguard for the minimisation form (read only when `symmetric` and `objective`
  // are set; pass an SPD matrix, e.g. the mass matrix M). When the LDLT factor of J has a
  // non-positive pivot in D — by Sylvester's law of inertia exactly when J is not positive
  // definite, so the Newton step need not descend E — J + μS is factorised instead, with μ growing
  // geometrically (NewtonOptions) until every pivot is positive. The shifted step is a descent
  // direction of E, so the line search can always make progress; near a strict minimiser J is
  // positive definite again and the iteration is plain Newton. Empty (default): no safeguard.
  SparseMatrix spd_shift;
  // Optional: called once, right after R(x₀) is evaluated, to add the size of the terms R
  // balances as found at x₀ (e.g. h‖∇V(q₁(x₀))‖ when the stiff part only shows there) to the
  // caller's residual_scale. Without it, a stiff step (hω ≫ 1) can ask for a residual below the
  // round-off of its own terms and fail although the iteration has converged.
  std::function<double()> scale_after_first_residual;
  // Optional: called after every jacobian() call, the size of the terms inside R's nonlinear
  // part at that iterate, e.g. (1−α)h·gradient_term_scale(∇²V, q^α) for a residual with
  // (1−α)h∇V(q^α). The rounding of R is about ε times that — not ε·residual_scale — when ∇V is
  // computed from coordinate differences and a stiff part sits near its rest length (h·K·q with
  // K = 1e8): the stopping test then asks for no less than kRoundoffFloor·(residual_scale +
  // this), instead of failing on noise.
  std::function<double()> inner_term_scale;
};

// ‖v‖₂ without the under- and overflow of squaring the entries: v is scaled by the power of two
// nearest its largest entry, so the result is bit-identical to v.norm() wherever that one neither
// underflows nor overflows (scaling by 2ᵏ is exact), and right from the smallest normal double
// to the largest, where v.norm() is 0 below ~1e-162 and inf above ~1e154. Every test and scale
// of the Newton solve and of the implicit methods' residual scales uses it, so a state of size
// 1e-300 or 1e+150 is solved like one of size 1 (tests/methods_test.cpp, scale-free).
double robust_norm(const Vec& v);
// Not for matrices: a sparse argument would otherwise convert to a Vec (Eigen allows it), which
// is not a Frobenius norm and, without Eigen's assertions, writes out of shape.
template <class Derived>
double robust_norm(const Eigen::SparseMatrixBase<Derived>&) = delete;
// ‖(a, b)‖₂ of the two stacked, the same way: bit-identical to √(‖a‖² + ‖b‖²) in range (the
// harness's phase-space errors ‖(q − q_ref, p − p_ref)‖₂ use it).
double robust_norm(const Vec& a, const Vec& b);

// The power of two 2⁻ᵏ that brings `magnitude` into [1, 2) (1 for 0, inf or NaN): multiplying by
// it is exact, so quantities compared with each other keep their order bit for bit.
double power_of_two_unit(double magnitude);

// ‖ |H|·|q| ‖₂ for a Hessian H = ∇²V(q): the size of the terms a gradient ∇V(q) sums when V is
// built from coordinate differences (springs, elements), so ε·‖|H||q|‖ estimates its rounding.
double gradient_term_scale(const SparseMatrix& H, const Vec& q);

struct NewtonResult {
  bool converged = false;
  // "" when converged; otherwise "newton_max_iter", "nan", "linear_solve_failed",
  // "line_search_failed" (no acceptable step length: R is at its round-off floor or x is near
  // a stationary point of the merit function that is not a root), "not_descent",
  // "objective_underflow" / "objective_overflow" (the objective, an energy quadratic in the
  // state, is not representable at this state's size: below ~1e-160 or above ~1e154; the
  // residual-only path, e.g. hp:solver=newton, has no such limit).
  std::string reason;
  int iterations = 0;            // Newton updates taken
  int linear_solves = 0;         // factorise + solve pairs
  int residual_evals = 0;        // including line-search trials
  int symbolic_analyses = 0;     // analyzePattern calls (0 when the cached pattern was reused)
  int shifted_iterations = 0;    // iterations whose Jacobian needed the SPD shift
  int shift_factorisations = 0;  // extra numeric factorisations spent on the shift
  // Numeric factorisations (or preconditioner set-ups, for CG) of any kind, shifted ones included;
  // below `iterations` under modified Newton.
  int factorizations = 0;
  int amg_setups = 0;       // BoomerAMG set-ups (cg_amg; also counted in factorizations)
  int cg_iterations = 0;    // CG iterations of every solve (cg, cg_ichol, cg_amg)
  double last_shift = 0.0;  // μ of the last shifted iteration
  bool polished = false;    // the polishing correction was taken (NewtonOptions::polish)
  // Converged because the Newton correction fell below kRoundoffFloor·‖x‖: x cannot be resolved
  // further in double precision, so the remaining ‖R‖ is the rounding of its terms (a stiff
  // term h·K·q whose own rounding ε·h·‖K‖‖q‖ exceeds tolerance·residual_scale), not an error.
  bool at_roundoff = false;
  double residual_norm = 0.0;
  // max(tolerance · residual_scale, kRoundoffFloor · (residual_scale + inner_term_scale)), as
  // last used
  double threshold = 0.0;
  std::vector<double> residual_history;  // ‖R‖ at x₀, x₁, … when options.record_history
};

// One line for StepStatus messages: "Newton stopped after 3 iterations: residual 1.2e-05 >
// 1e-12 (newton_max_iter)".
std::string describe(const NewtonResult& result);

// Central-difference step for unknown j: δ_j = ε^(1/3)·max(|x_j|, ‖x‖∞), which balances
// truncation (δ²) and round-off (ε/δ) relative to the size of x — scale-free, so a state of size
// 1e-100 is not differenced with steps of 1e-5 — and ε^(1/3) when x is exactly zero.
double central_difference_step(const Vec& x, Eigen::Index j);

// ∂f/∂x at x by central differences, one column per unknown, with the steps above. Dense
// columns and 2·dim(x) evaluations of f: for Jacobian pieces a problem does not provide, on
// small systems.
SparseMatrix central_difference_jacobian(const std::function<void(const Vec& x, Vec& f)>& f,
                                         const Vec& x);

class NewtonSolver {
 public:
  explicit NewtonSolver(NewtonOptions options = {});
  ~NewtonSolver();
  NewtonSolver(NewtonSolver&&) noexcept;
  NewtonSolver& operator=(NewtonSolver&&) noexcept;

  // Solves system.R(x) = 0 starting from x (overwritten by the last accepted iterate, also on
  // failure). Never throws on numerical trouble; the result says what happened.
  NewtonResult solve(const NewtonSystem& system, Vec& x, double residual_scale);

  // Drops the cached symbolic and numeric factorisations (e.g. on Integrator::reset()).
  void forget_pattern();

  const NewtonOptions& options() const { return options_; }
  NewtonOptions& options() { return options_; }

 private:
  struct Factorisation;
  NewtonOptions options_;
  std::unique_ptr<Factorisation> factorisation_;
};

}  // namespace geomint
