// SUNDIALS 6.4 wrappers: CVODE (BDF/Adams), IDA on y' − f(t, y) = 0, ARKODE explicit RK (Hindmarsh
// et al., ACM TOMS 31 (2005); user guides v6.4.1 at sundials.readthedocs.io). Each adaptive_step
// is one internal step: *_ONE_STEP with the stop time at t_stop.
#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <fmt/format.h>
#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <type_traits>
#include <vector>

#include "integrators/adaptive.hpp"
#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// ---------------------------------------------------------------------------------------------
// RAII for SUNDIALS handles. Members holding them are declared context first, solver memory
// last, so destruction frees the solver before the objects it references.

struct ContextDeleter {
  void operator()(SUNContext context) const { SUNContext_Free(&context); }
};
struct VectorDeleter {
  void operator()(N_Vector vector) const { N_VDestroy(vector); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix matrix) const { SUNMatDestroy(matrix); }
};
struct LinearSolverDeleter {
  void operator()(SUNLinearSolver solver) const { SUNLinSolFree(solver); }
};
struct CvodeDeleter {
  void operator()(void* memory) const { CVodeFree(&memory); }
};
struct IdaDeleter {
  void operator()(void* memory) const { IDAFree(&memory); }
};
struct FreeDeleter {
  void operator()(char* text) const { std::free(text); }
};

using ContextPtr = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using VectorPtr = std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorDeleter>;
using MatrixPtr = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;
using LinearSolverPtr =
    std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinearSolverDeleter>;
template <typename Deleter>
using MemoryPtr = std::unique_ptr<void, Deleter>;

// The *GetReturnFlagName functions return malloc'ed text.
std::string flag_name(char* (*lookup)(long), int flag) {
  const std::unique_ptr<char, FreeDeleter> name(lookup(flag));
  return name ? std::string(name.get()) : std::string("unknown flag");
}

Eigen::Map<const Vec> view(N_Vector v) {
  return {N_VGetArrayPointer(v), static_cast<Eigen::Index>(N_VGetLength(v))};
}
Eigen::Map<Vec> view_mutable(N_Vector v) {
  return {N_VGetArrayPointer(v), static_cast<Eigen::Index>(N_VGetLength(v))};
}

// A = scale·J + shift·I into a dense SUNMatrix (column-major).
void fill_dense(const SparseMatrix& jacobian, double scale, double shift, SUNMatrix matrix) {
  SUNMatZero(matrix);
  for (int col = 0; col < jacobian.outerSize(); ++col) {
    sunrealtype* column = SUNDenseMatrix_Column(matrix, col);
    for (SparseMatrix::InnerIterator it(jacobian, col); it; ++it) {
      column[it.row()] += scale * it.value();
    }
    column[col] += shift;
  }
}

AdaptiveSettings read_settings(Params& params) {
  return read_adaptive_settings(
      params,
      "maximum number of internal steps over the whole run (the run fails with flag -1, "
      "TOO_MUCH_WORK, when it is reached)");
}

// ---------------------------------------------------------------------------------------------
// Shared plumbing: context, callbacks into the Problem (first_order_rhs/first_order_jacobian),
// error capture and the run-total step limit.
//
// reset() creates the solver (setup problems: AdaptiveIntegrator::setup_status_). The solver's
// own y is the state of record.
class SundialsIntegrator : public AdaptiveIntegrator {
 protected:
  SundialsIntegrator(const AdaptiveSettings& settings, std::string library)
      : AdaptiveIntegrator(settings, "SUNDIALS wrappers"), library_(std::move(library)) {}

  // Base reset, a fresh context and y0 = (q, p, 0 …) (y0 = q on a first-order-only problem):
  // `extra` zero components after (q, p) for DAE unknowns (multipliers). Returns false
  // (setup_status_ set) on failure.
  bool begin_reset(const Problem& problem, const State& state, int extra = 0) {
    begin_adaptive_reset(problem, state, 0.0);
    library_message_.clear();
    extra_rhs_evals_ = extra_jacobian_evals_ = 0;
    dof_ = problem.dof();
    ode_size_ = problem.first_order_size();
    n_ = ode_size_ + extra;
    y_.reset();  // before the context it was created in
    context_.reset();
    SUNContext context = nullptr;
    if (SUNContext_Create(nullptr, &context) != 0) {
      return setup_failed(-1, "SUNContext_Create failed");
    }
    context_.reset(context);
    y_.reset(N_VNew_Serial(n_, context_.get()));
    if (!y_) return setup_failed(-1, "N_VNew_Serial failed");
    auto y = view_mutable(y_.get());
    y.setZero();
    problem.pack_first_order(state, y.data());
    return true;
  }

  // Records a failed library call during setup (only the first failure is kept).
  bool setup_failed(int flag, const std::string& what) {
    if (setup_status_.ok) {
      setup_status_ = StepStatus::failure(fmt::format("{}_flag_{}", library_, flag),
                                          fmt::format("{} setup: {}", library_, what));
    }
    return false;
  }
  bool check_setup(int flag, const char* call) {
    if (flag >= 0) return true;
    return setup_failed(flag, fmt::format("{} returned {} {}", call, flag, library_message_));
  }

  // SUNDIALS applies mxstep per call, and in ONE_STEP mode every call takes one step, so the
  // run-total limit is enforced by ready_to_step and reported as the library's TOO_MUCH_WORK
  // flag (-1).
  StepStatus step_budget_exhausted(double) const override {
    return StepStatus::failure(
        fmt::format("{}_flag_-1", library_),
        fmt::format("{}: too much work: max_steps={} internal steps taken before t={:.6g}",
                    library_, settings_.max_steps, t_));
  }

  StepStatus library_failure(int flag, char* (*lookup)(long int)) {
    std::string message =
        fmt::format("{} returned {} ({})", library_, flag_name(lookup, flag), flag);
    if (!library_message_.empty()) message += ": " + library_message_;
    if (!callback_error_.empty()) message += "; callback error: " + callback_error_;
    return StepStatus::failure(fmt::format("{}_flag_{}", library_, flag), message);
  }

  // Copies the solver's y (the state of record) into State. A return at the stop time is
  // stamped with t_stop exactly, so the caller's loop ends on it without a sliver step.
  void publish(N_Vector y, double t_returned, double t_stop, bool at_stop, State& state) {
    problem_->unpack_first_order(N_VGetArrayPointer(y), state);
    t_ = at_stop ? t_stop : t_returned;
    state.t = t_;
  }

  // y' = f(t, y). A non-finite derivative is reported as recoverable (positive return), so the
  // solver retries with a smaller step; an exception is unrecoverable and its text is kept.
  int evaluate_rhs(double t, N_Vector y, N_Vector ydot) noexcept {
    try {
      y_buffer_ = view(y);
      problem_->first_order_rhs(t, y_buffer_, ydot_buffer_);
      if (!ydot_buffer_.allFinite()) return 1;
      view_mutable(ydot) = ydot_buffer_;
      return 0;
    } catch (const std::exception& error) {
      callback_error_ = error.what();
      return -1;
    }
  }

  // jacobian_ = ∂f/∂y at (t, y).
  int evaluate_jacobian(double t, N_Vector y) noexcept {
    try {
      y_buffer_ = view(y);
      problem_->first_order_jacobian(t, y_buffer_, jacobian_);
      jacobian_.makeCompressed();
      return 0;
    } catch (const std::exception& error) {
      callback_error_ = error.what();
      return -1;
    }
  }

  // Keeps the library's last error text for the failure message instead of printing it.
  static void record_message(int, const char* module, const char* function, char* message,
                             void* self) {
    static_cast<SundialsIntegrator*>(self)->library_message_ = fmt::format(
        "[{} {}] {}", module ? module : "", function ? function : "", message ? message : "");
  }

  std::string library_;  // flag prefix: "cvode", "ida", "arkode"
  int dof_ = 0;
  int ode_size_ = 0;  // length of the ODE part of y: 2·dof, or dof (first-order-only problems)
  int n_ = 0;
  std::string library_message_;
  long extra_rhs_evals_ = 0;       // evaluations made outside the library (IDA's y'(0))
  long extra_jacobian_evals_ = 0;  // ... (the KLU sparsity probe)
  Vec y_buffer_, ydot_buffer_;
  SparseMatrix jacobian_;

  // Declared in this order so that derived classes' solver memory (declared later) goes first.
  ContextPtr context_;
  VectorPtr y_;
};

// ---------------------------------------------------------------------------------------------
// CVODE: variable-order BDF (stiff) or Adams–Moulton (non-stiff), Newton iteration with the
// analytic Jacobian when the problem has a Hessian, else SUNDIALS's difference quotients.
// MethodInfo::order is the maximum order; the registry-driven order fits skip adaptive methods.
//
// Newton setup frequency: CVODE's default reuses the Jacobian and the factored I − γJ for up to
// 20 steps (modified Newton), which is right for stiff problems whose Jacobian changes slowly.
// At tight tolerances on an orbit the stale matrix leaves an iteration error as large as the
// truncation error: kepler:e=0.6, rtol=1e-10, atol=1e-12, t=20 measured error_final 1.04e-6 with
// CVODE's defaults (setup every 20 steps, Jacobian every 51) and 9.97e-7 with setup_every=20,
// but 3.01e-7 with a fresh setup every step (setup_every=1) and 5.83e-7 with the nonlinear
// solve made nearly exact (setup_every=1, nonlin_conv_coef=1e-6): the remaining 3-6e-7 is the
// BDF truncation error. So setup_every=1 is the default here (3.6x the wall time on Kepler);
// setup_every=20 restores CVODE's modified Newton for large stiff problems.

enum class LinearSolverKind { kDense, kKlu };

class Cvode final : public SundialsIntegrator {
 public:
  Cvode(bool bdf, const AdaptiveSettings& settings, int max_order, LinearSolverKind solver,
        long setup_every, double nonlin_conv_coef, int max_nonlin_iters)
      : SundialsIntegrator(settings, "cvode"),
        bdf_(bdf),
        max_order_(max_order),
        solver_kind_(solver),
        setup_every_(setup_every),
        nonlin_conv_coef_(nonlin_conv_coef),
        max_nonlin_iters_(max_nonlin_iters) {}

  MethodInfo info() const override {
    // kGeneralLagrangian: CVODE sees only first_order_rhs/_jacobian, which a non-separable problem
    // gives as Hamilton's equations of its L (problems/problem.cpp).
    return {bdf_ ? "cvode_bdf" : "cvode_adams", max_order_,
            kImplicit | kAdaptive | kFirstOrderCapable | kGeneralLagrangian,
            bdf_ ? "SUNDIALS CVODE, variable-order BDF (CVODE user guide v6.4.1, §2.1)"
                 : "SUNDIALS CVODE, variable-order Adams-Moulton (CVODE user guide v6.4.1, §2.1)"};
  }

  void reset(const Problem& problem, const State& state, double) override {
    memory_.reset();
    linear_solver_.reset();
    matrix_.reset();
    if (!begin_reset(problem, state)) return;
    memory_.reset(CVodeCreate(bdf_ ? CV_BDF : CV_ADAMS, context_.get()));
    if (!memory_) {
      setup_failed(-1, "CVodeCreate failed");
      return;
    }
    void* cvode = memory_.get();
    if (!check_setup(CVodeSetErrHandlerFn(cvode, &record_message, this), "CVodeSetErrHandlerFn") ||
        !check_setup(CVodeInit(cvode, &rhs, state.t, y_.get()), "CVodeInit") ||
        !check_setup(CVodeSetUserData(cvode, this), "CVodeSetUserData") ||
        !check_setup(CVodeSStolerances(cvode, settings_.rtol, settings_.atol),
                     "CVodeSStolerances") ||
        !check_setup(CVodeSetMaxOrd(cvode, max_order_), "CVodeSetMaxOrd") ||
        !check_setup(CVodeSetLSetupFrequency(cvode, setup_every_), "CVodeSetLSetupFrequency") ||
        !check_setup(CVodeSetNonlinConvCoef(cvode, nonlin_conv_coef_), "CVodeSetNonlinConvCoef") ||
        !check_setup(CVodeSetMaxNonlinIters(cvode, max_nonlin_iters_), "CVodeSetMaxNonlinIters")) {
      return;
    }
    // The dense path takes the analytic Jacobian where the problem has a Hessian (or rhs_jacobian)
    // and CVODE's difference quotient otherwise, a non-separable problem included (its committed
    // rows, results/charged_particle, were measured so). KLU needs the matrix itself, which a
    // non-separable problem gives analytically: the Jacobian of Hamilton's equations of its L.
    const bool analytic = solver_kind_ == LinearSolverKind::kKlu
                              ? has_analytic_first_order_jacobian(problem)
                              : problem.has_first_order_jacobian();
    analytic_jacobian_ = analytic;
    if (solver_kind_ == LinearSolverKind::kKlu) {
      if (!analytic) {
        setup_status_ = StepStatus::failure(
            "needs_hessian",
            "linear_solver=klu needs the sparse Jacobian, i.e. a problem Hessian or rhs_jacobian");
        return;
      }
      // Size the sparse matrix from the Jacobian at y0 plus its diagonal (see fill_sparse).
      ++extra_jacobian_evals_;
      if (evaluate_jacobian(state.t, y_.get()) != 0) {
        setup_failed(-1, "first_order_jacobian threw: " + callback_error_);
        return;
      }
      matrix_.reset(SUNSparseMatrix(n_, n_, jacobian_.nonZeros() + n_, CSC_MAT, context_.get()));
      if (matrix_) linear_solver_.reset(SUNLinSol_KLU(y_.get(), matrix_.get(), context_.get()));
    } else {
      matrix_.reset(SUNDenseMatrix(n_, n_, context_.get()));
      if (matrix_) linear_solver_.reset(SUNLinSol_Dense(y_.get(), matrix_.get(), context_.get()));
    }
    if (!matrix_ || !linear_solver_) {
      setup_failed(-1, "could not create the matrix or linear solver");
      return;
    }
    pattern_columns_.clear();
    pattern_rows_.clear();
    if (!check_setup(CVodeSetLinearSolver(cvode, linear_solver_.get(), matrix_.get()),
                     "CVodeSetLinearSolver")) {
      return;
    }
    if (analytic) check_setup(CVodeSetJacFn(cvode, &jacobian), "CVodeSetJacFn");
    // A Jacobian at most as old as the factored matrix (CVODE's default re-evaluates it only
    // every 51 steps even when it factors more often).
    check_setup(CVodeSetJacEvalFrequency(cvode, setup_every_), "CVodeSetJacEvalFrequency");
  }

  StepStatus adaptive_step(const Problem& problem, State& state, double t_stop) override {
    StepStatus status;
    if (!ready_to_step(problem, state, t_stop, status)) return status;
    void* cvode = memory_.get();
    int flag = CVodeSetStopTime(cvode, t_stop);
    double t_returned = t_;
    if (flag >= 0) flag = CVode(cvode, t_stop, y_.get(), &t_returned, CV_ONE_STEP);
    update_counters();
    if (flag < 0) return library_failure(flag, &CVodeGetReturnFlagName);
    publish(y_.get(), t_returned, t_stop, flag == CV_TSTOP_RETURN || t_returned >= t_stop, state);
    return StepStatus::success();
  }

 private:
  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* self) {
    return static_cast<Cvode*>(self)->evaluate_rhs(t, y, ydot);
  }

  static int jacobian(sunrealtype t, N_Vector y, N_Vector, SUNMatrix matrix, void* self, N_Vector,
                      N_Vector, N_Vector) {
    auto& cvode = *static_cast<Cvode*>(self);
    if (const int flag = cvode.evaluate_jacobian(t, y); flag != 0) return flag;
    if (cvode.solver_kind_ == LinearSolverKind::kDense) {
      fill_dense(cvode.jacobian_, 1.0, 0.0, matrix);
      return 0;
    }
    return cvode.fill_sparse(matrix);
  }

  // Writes jacobian_ into the CSC matrix with an explicit (possibly zero) diagonal: CVODE forms
  // I − γJ in place, and a stored diagonal keeps that from restructuring the matrix. KLU
  // re-factors with the symbolic analysis of its first factorization, so a changed pattern (a
  // Hessian entry that became an exact zero and was dropped) forces a new analysis.
  int fill_sparse(SUNMatrix matrix) {
    columns_.assign(1, 0);
    rows_.clear();
    values_.clear();
    for (int col = 0; col < n_; ++col) {
      bool diagonal_done = false;
      for (SparseMatrix::InnerIterator it(jacobian_, col); it; ++it) {
        if (!diagonal_done && it.row() >= col) {
          if (it.row() > col) {
            rows_.push_back(col);
            values_.push_back(0.0);
          }
          diagonal_done = true;
        }
        rows_.push_back(it.row());
        values_.push_back(it.value());
      }
      if (!diagonal_done) {
        rows_.push_back(col);
        values_.push_back(0.0);
      }
      columns_.push_back(static_cast<sunindextype>(rows_.size()));
    }
    const auto nonzeros = static_cast<sunindextype>(rows_.size());
    if (SUNSparseMatrix_NNZ(matrix) < nonzeros &&
        SUNSparseMatrix_Reallocate(matrix, nonzeros) != 0) {
      callback_error_ = "SUNSparseMatrix_Reallocate failed";
      return -1;
    }
    std::copy(columns_.begin(), columns_.end(), SUNSparseMatrix_IndexPointers(matrix));
    std::copy(rows_.begin(), rows_.end(), SUNSparseMatrix_IndexValues(matrix));
    std::copy(values_.begin(), values_.end(), SUNSparseMatrix_Data(matrix));
    if (columns_ != pattern_columns_ || rows_ != pattern_rows_) {
      if (!pattern_columns_.empty() &&
          SUNLinSol_KLUReInit(linear_solver_.get(), matrix, nonzeros, SUNKLU_REINIT_PARTIAL) != 0) {
        callback_error_ = "SUNLinSol_KLUReInit failed";
        return -1;
      }
      pattern_columns_ = columns_;
      pattern_rows_ = rows_;
    }
    return 0;
  }

  void update_counters() {
    void* cvode = memory_.get();
    long steps = 0, rhs_evals = 0, rhs_evals_ls = 0, jacobian_evals = 0, newton_iters = 0,
         error_test_fails = 0, solve_fails = 0;
    CVodeGetNumSteps(cvode, &steps);
    CVodeGetNumRhsEvals(cvode, &rhs_evals);
    CVodeGetNumLinRhsEvals(cvode, &rhs_evals_ls);
    CVodeGetNumJacEvals(cvode, &jacobian_evals);
    CVodeGetNumNonlinSolvIters(cvode, &newton_iters);
    CVodeGetNumErrTestFails(cvode, &error_test_fails);
    CVodeGetNumStepSolveFails(cvode, &solve_fails);
    counters_.steps = steps;
    counters_.force_evals = rhs_evals + rhs_evals_ls + extra_rhs_evals_;
    // Difference-quotient Jacobians evaluate no Hessian; their f calls are in rhs_evals_ls.
    counters_.hessian_evals = analytic_jacobian_ ? jacobian_evals + extra_jacobian_evals_ : 0;
    counters_.newton_iters = newton_iters;
    counters_.linear_solves = newton_iters;  // direct solver: one solve per Newton iteration
    counters_.rejected = error_test_fails + solve_fails;
  }

  bool bdf_;
  bool analytic_jacobian_ = false;
  int max_order_;
  LinearSolverKind solver_kind_;
  long setup_every_;
  double nonlin_conv_coef_;
  int max_nonlin_iters_;
  std::vector<sunindextype> columns_, rows_, pattern_columns_, pattern_rows_;
  std::vector<double> values_;
  MatrixPtr matrix_;
  LinearSolverPtr linear_solver_;
  MemoryPtr<CvodeDeleter> memory_;
};

// ---------------------------------------------------------------------------------------------
// IDA on F(t, y, y') = y' − f(t, y) = 0 (`index=ode`, the default). The initial y'(0) =
// f(0, y0) is consistent by construction, so IDACalcIC is not needed. Newton matrix dF/dy +
// c_j dF/dy' = c_j I − ∂f/∂y, dense.
//
// On a constrained problem (docs/METHOD.md §3, Hairer & Wanner II §VII.1, Brenan, Campbell &
// Petzold 1996 §6.2) `index=3` solves the DAE itself in y = (q, p, λ):
//   q' = M⁻¹p,  p' = −∇V + F − Gᵀλ,  0 = g(q);
// `index=2` the stabilised Gear–Gupta–Leimkuhler form in y = (q, p, λ, μ):
//   q' = M⁻¹(p − Gᵀμ),  p' = −∇V + F − Gᵀλ,  0 = G M⁻¹p,  0 = g(q)
// (μ = 0 on exact solutions; it projects q' back onto g = 0). Time-dependent constraints
// (car_axis) use g(q, t), G(q, t) and, at index 2, G M⁻¹p + ∂g/∂t = 0. The error test leaves out
// what the index makes unreliable (IDASetId + IDASetSuppressAlg): λ, μ, and at index 3 also p,
// whose local error estimate is O(h^(k−1)) there. Consistent (y, y') at t0 come from the problem's
// own multipliers (Problem::multipliers, μ = 0), exact to round-off: IDACalcIC only treats
// index-1 systems (IDA user guide §2.1), so it does not apply to either form. The Newton
// Jacobian is IDA's dense difference quotient.
class Ida final : public SundialsIntegrator {
 public:
  Ida(const AdaptiveSettings& settings, int max_order, int index, int max_nonlin_iters,
      double nonlin_conv_coef, std::optional<double> multiplier_atol)
      : SundialsIntegrator(settings, "ida"),
        max_order_(max_order),
        index_(index),
        max_nonlin_iters_(max_nonlin_iters),
        nonlin_conv_coef_(nonlin_conv_coef),
        multiplier_atol_(multiplier_atol) {}

  MethodInfo info() const override {
    if (index_ == 0) {
      // y' − f(t, y) = 0 sees only first_order_rhs and its Jacobian: on a non-separable problem
      // Hamilton's equations of its L (docs/MECHANICS_GENERAL.md §1), with the analytic Jacobian.
      return {"ida", max_order_, kImplicit | kAdaptive | kFirstOrderCapable | kGeneralLagrangian,
              "SUNDIALS IDA, variable-order BDF on the residual form (IDA user guide v6.4.1, §2)"};
    }
    // The residual below takes p' = L_q + F − Gᵀλ from the problem's LagrangianSystem on the
    // general kind (andrews: M(q) with constraints), so both forms run it.
    return {
        "ida", max_order_,
        kImplicit | kAdaptive | kConstrained | kConstraintsOnly | kRheonomic | kGeneralLagrangian,
        index_ == 3 ? "SUNDIALS IDA, BDF on the index-3 constrained equations of motion "
                      "(Brenan, Campbell & Petzold 1996 §6.2)"
                    : "SUNDIALS IDA, BDF on the stabilised index-2 (Gear-Gupta-Leimkuhler "
                      "1985) constrained equations of motion"};
  }

  void reset(const Problem& problem, const State& state, double) override {
    memory_.reset();
    linear_solver_.reset();
    matrix_.reset();
    yp_.reset();
    id_.reset();
    constraints_ = index_ == 0 ? nullptr : &constraints_of(problem);
    constraint_count_ = index_ == 0 ? 0 : constraints_->constraint_count();
    const int multipliers = index_ == 3 ? constraint_count_ : 2 * constraint_count_;
    if (!begin_reset(problem, state, multipliers)) return;
    yp_.reset(N_VNew_Serial(n_, context_.get()));
    if (!yp_) {
      setup_failed(-1, "N_VNew_Serial failed");
      return;
    }
    if (index_ != 0 && !consistent_start(problem, state)) return;
    ++extra_rhs_evals_;
    if (evaluate_residual(state.t, y_.get(), nullptr, yp_.get()) != 0) {
      setup_failed(-1, "f(t0, y0) is not finite or threw " + callback_error_);
      return;
    }
    memory_.reset(IDACreate(context_.get()));
    if (!memory_) {
      setup_failed(-1, "IDACreate failed");
      return;
    }
    void* ida = memory_.get();
    if (!check_setup(IDASetErrHandlerFn(ida, &record_message, this), "IDASetErrHandlerFn") ||
        !check_setup(IDAInit(ida, &residual, state.t, y_.get(), yp_.get()), "IDAInit") ||
        !check_setup(IDASetUserData(ida, this), "IDASetUserData") ||
        !check_setup(IDASStolerances(ida, settings_.rtol, settings_.atol), "IDASStolerances") ||
        !check_setup(IDASetMaxOrd(ida, max_order_), "IDASetMaxOrd") ||
        !check_setup(IDASetMaxNonlinIters(ida, max_nonlin_iters_), "IDASetMaxNonlinIters") ||
        !check_setup(IDASetNonlinConvCoef(ida, nonlin_conv_coef_), "IDASetNonlinConvCoef")) {
      return;
    }
    if (index_ != 0 && !exclude_from_error_test(ida)) return;
    if (index_ != 0 && multiplier_atol_ && !loosen_multipliers(ida)) return;
    if (index_ == 2 && !multiplier_atol_ &&
        !check_setup(IDAWFtolerances(ida, &step_scaled_weights), "IDAWFtolerances")) {
      return;
    }
    first_step_ = 0;
    index3_started_ = false;
    matrix_.reset(SUNDenseMatrix(n_, n_, context_.get()));
    if (matrix_) linear_solver_.reset(SUNLinSol_Dense(y_.get(), matrix_.get(), context_.get()));
    if (!matrix_ || !linear_solver_) {
      setup_failed(-1, "could not create the dense matrix or linear solver");
      return;
    }
    if (!check_setup(IDASetLinearSolver(ida, linear_solver_.get(), matrix_.get()),
                     "IDASetLinearSolver")) {
      return;
    }
    analytic_jacobian_ = index_ == 0 && has_analytic_first_order_jacobian(problem);
    if (analytic_jacobian_) check_setup(IDASetJacFn(ida, &jacobian), "IDASetJacFn");
  }

  StepStatus adaptive_step(const Problem& problem, State& state, double t_stop) override {
    StepStatus status;
    if (!ready_to_step(problem, state, t_stop, status)) return status;
    // IDA's own too-much-accuracy test (unit roundoff times the weighted RMS norm of y above 1)
    // comes after its initial-step estimate, which overflows first at such tolerances and then
    // reports "tstop is behind current t". The same test here names the real cause.
    status = check_tolerances_above_roundoff(N_VGetArrayPointer(y_.get()), ode_size_, "ida_flag_-2",
                                             "ida (IDA_TOO_MUCH_ACC)");
    if (!status.ok) return status;
    void* ida = memory_.get();
    int flag = IDASetStopTime(ida, t_stop);
    if (flag >= 0 && index_ == 2 && !multiplier_atol_ && first_step_ == 0) {
      first_step_ = initial_step(t_stop);
      flag = IDASetInitStep(ida, first_step_);
    }
    if (flag >= 0 && index_ == 3 && !index3_started_) {
      index3_started_ = true;
      if (const double step = index3_initial_step(t_stop); step > 0) {
        flag = IDASetInitStep(ida, step);
      }
    }
    double t_returned = t_;
    if (flag >= 0) flag = IDASolve(ida, t_stop, &t_returned, y_.get(), yp_.get(), IDA_ONE_STEP);
    update_counters();
    if (flag < 0) return library_failure(flag, &IDAGetReturnFlagName);
    publish(y_.get(), t_returned, t_stop, flag == IDA_TSTOP_RETURN || t_returned >= t_stop, state);
    return StepStatus::success();
  }

 private:
  // λ(t0) from the problem (the multipliers that keep d²g/dt² = 0), μ = 0, and y'(t0) from the
  // differential equations; the algebraic components of y' are not used by the residual.
  bool consistent_start(const Problem& problem, const State& state) {
    try {
      auto y = view_mutable(y_.get());
      y.segment(2 * dof_, constraint_count_) = problem.multipliers(state.t, state.q, state.p);
      return true;
    } catch (const std::exception& error) {
      return setup_failed(-1, std::string("initial multipliers: ") + error.what());
    }
  }

  // The multipliers are outside the error test but not outside IDA's Newton convergence test,
  // which weighs them by 1/(rtol|λ| + atol). On the 9-coordinate rigid bodies the default
  // atol = 1e-10 there makes the corrector fail at t = 0 (results/rigid_body/README.md, "IDA on
  // the attitude problems"); a looser absolute tolerance for λ and μ alone lets it run.
  bool loosen_multipliers(void* ida) {
    VectorPtr tolerances(N_VNew_Serial(n_, context_.get()));
    if (!tolerances) return setup_failed(-1, "N_VNew_Serial failed");
    auto atol = view_mutable(tolerances.get());
    atol.setConstant(settings_.atol);
    atol.tail(n_ - 2 * dof_).setConstant(*multiplier_atol_);
    return check_setup(IDASVtolerances(ida, settings_.rtol, tolerances.get()), "IDASVtolerances");
  }

  // Index 2: the error weights of λ and μ, which only IDA's Newton convergence test uses (they
  // are outside the error test). Their Newton increments carry the round-off of the constraint
  // rows amplified by c_j = α/h: δμ ≈ c_j (G M⁻¹Gᵀ)⁻¹ r_g with r_g ≈ ε|q| from g(q), likewise δλ
  // from the ε|p| of G M⁻¹p. With the fixed weights 1/(rtol|λ| + atol) that noise fails the test
  // at the tiny first steps (from p(0) = 0 and a tight atol) as soon as g(q) rounds to a nonzero
  // value, whatever the step: IDA_CONV_FAIL at t ≈ 0 on rod_chain with a mass ratio or length
  // other than 1, on the rigid bodies, or car_axis at rtol 1e-10. So each multiplier's weight is
  // the fixed one, capped at kRoundoffMargin⁻¹ × the weight under which its round-off noise would
  // count 1: the multipliers' effect over the step in the differential variables' weights,
  // h ‖G_i ∘ w(p)‖₂ for λ_i and h ‖G_i M⁻¹ ∘ w(q)‖₂ for μ_i (the h-scaling of index-2 variables,
  // as RADAU5's NIND2 scaling of Hairer & Wanner), over the round-off of p resp. q in those
  // weights, ε max_j |p_j| w(p)_j resp. ε max_j |q_j| w(q)_j. At ordinary steps and tolerances the
  // cap is above the fixed weight, which then holds: the h-scaled weights alone (commit e35f6b9)
  // let λ settle only to tol/h and cost accuracy, error 8.9e-9 against 3.6e-9 capped on
  // IdaDae.Index2AndIndex3SolveTheCartesianPendulum (rtol 1e-10). IDA calls this at every step
  // start, with h the step about to be tried; before the first step h is the first step set by
  // initial_step().
  static constexpr double kRoundoffMargin = 100;
  int evaluate_step_scaled_weights(N_Vector y_vector, N_Vector weights_vector) noexcept {
    try {
      const auto y = view(y_vector);
      auto w = view_mutable(weights_vector);
      const int n = dof_, m = constraint_count_;
      // What IDASStolerances would set, for every component.
      w = (settings_.rtol * y.array().abs() + settings_.atol).inverse().matrix();
      long steps = 0;
      double h = first_step_, t = t_;
      IDAGetNumSteps(memory_.get(), &steps);
      if (steps > 0) {
        IDAGetCurrentStep(memory_.get(), &h);
        IDAGetCurrentTime(memory_.get(), &t);
      }
      h = std::abs(h);
      q_ = y.head(n);
      constraints_->constraint_jacobian_at(t, q_, G_);
      Vec on_p = Vec::Zero(m), on_q = Vec::Zero(m);
      const MassOperator mass(*problem_);
      if (mass.is_constant_diagonal()) {
        const Vec& inverse_mass = mass.constant_inverse_diagonal();
        for (int col = 0; col < G_.outerSize(); ++col) {
          for (SparseMatrix::InnerIterator it(G_, col); it; ++it) {
            on_p[it.row()] += std::pow(it.value() * w[n + col], 2);
            on_q[it.row()] += std::pow(it.value() * inverse_mass[col] * w[col], 2);
          }
        }
      } else {
        // M(q): the rows of G M⁻¹ = (M⁻¹Gᵀ)ᵀ, dense (a few constraints).
        Eigen::MatrixXd inverse_mass_Gt = Eigen::MatrixXd(G_).transpose();
        mass.solve_columns(q_, inverse_mass_Gt);
        const Eigen::MatrixXd G_dense(G_);
        for (int i = 0; i < m; ++i) {
          on_p[i] = G_dense.row(i).transpose().cwiseProduct(w.segment(n, n)).squaredNorm();
          on_q[i] = inverse_mass_Gt.col(i).cwiseProduct(w.head(n)).squaredNorm();
        }
      }
      const double unit_roundoff = std::numeric_limits<double>::epsilon();
      const double p_noise = kRoundoffMargin * unit_roundoff *
                             y.segment(n, n).cwiseAbs().cwiseProduct(w.segment(n, n)).maxCoeff();
      const double q_noise =
          kRoundoffMargin * unit_roundoff * y.head(n).cwiseAbs().cwiseProduct(w.head(n)).maxCoeff();
      for (int i = 0; i < m; ++i) {
        // p = 0 (a start at rest) or q = 0 carries no round-off to amplify: the fixed weight.
        if (p_noise > 0) w[2 * n + i] = std::min(w[2 * n + i], h * std::sqrt(on_p[i]) / p_noise);
        if (q_noise > 0) {
          w[2 * n + m + i] = std::min(w[2 * n + m + i], h * std::sqrt(on_q[i]) / q_noise);
        }
      }
      // A zero weight (a constraint row without entries, h = 0) would make IDA's difference
      // quotient increment 1/w infinite.
      return w.allFinite() && w.minCoeff() > 0 ? 0 : -1;
    } catch (const std::exception& error) {
      callback_error_ = error.what();
      return -1;
    }
  }
  static int step_scaled_weights(N_Vector y, N_Vector weights, void* self) {
    return static_cast<Ida*>(self)->evaluate_step_scaled_weights(y, weights);
  }

  // IDA's own first step (IDA user guide v6.4.1 §2.1, IDASolve): 0.001 |t_stop − t0|, cut to
  // 0.5 / ‖y'(t0)‖ (weighted RMS over the differential components), here because the step-scaled
  // weights need it before IDA computes it.
  double initial_step(double t_stop) const {
    const auto y = view(y_.get());
    const auto yp = view(yp_.get());
    const int differential = 2 * dof_;
    const Vec weights =
        (settings_.rtol * y.head(differential).array().abs() + settings_.atol).inverse().matrix();
    const double yp_norm =
        std::sqrt(yp.head(differential).cwiseProduct(weights).squaredNorm() / n_);
    double h = 0.001 * std::abs(t_stop - t_);
    if (yp_norm * h > 0.5) h = 0.5 / yp_norm;
    return h;
  }

  // Index 3: IDA's own first step, 0.001 |t_stop − t0| cut to 0.5/‖q'‖ (its weighted RMS norm
  // skips the components outside the error test, here p and λ), is ~5e-9 on a start in motion
  // with tight weights (the rigid bodies: ‖Q'‖ ≈ 1, weights 1/(1e-8|Q| + 1e-10)); there the
  // index-3 Newton matrix, whose λ block scales as 1/h², turns the round-off of g(q) into
  // corrections no convergence test accepts: IDA_CONV_FAIL at t ≈ 1e-8 (results/rigid_body/
  // README.md). A first BDF step integrates a constant q' exactly: its local error is ½h²q''. So
  // when IDA's step is shorter than the one where that error is 1 in the error weights,
  // ‖q''‖_w h² = 1 with q'' = M⁻¹p' from the consistent start, the first step is that one, never
  // longer than 0.001 |t_stop − t0|. 0 = IDA's own (a start at rest: q' = 0 gives IDA's upper
  // bound), so those runs are unchanged.
  double index3_initial_step(double t_stop) const {
    const auto y = view(y_.get());
    const auto yp = view(yp_.get());
    const Vec weights = (settings_.rtol * y.head(dof_).array().abs() + settings_.atol).inverse();
    const double upper = 0.001 * std::abs(t_stop - t_);
    const double q_rate_norm = std::sqrt(yp.head(dof_).cwiseProduct(weights).squaredNorm() / n_);
    const double ida_step = q_rate_norm * upper > 0.5 ? 0.5 / q_rate_norm : upper;
    // On a mass M(q) q'' = M⁻¹(p' − Ṁv): M⁻¹p' is exact only from rest (andrews starts there);
    // in motion it is an estimate, which is all a first step needs.
    const Vec q_second = MassOperator(*problem_).solve(y.head(dof_), yp.segment(dof_, dof_));
    const double q_second_norm = std::sqrt(q_second.cwiseProduct(weights).squaredNorm() / dof_);
    if (!(q_second_norm > 0) || !std::isfinite(q_second_norm)) return 0;
    const double error_step = std::min(upper, 1.0 / std::sqrt(q_second_norm));
    return error_step > ida_step ? error_step : 0;
  }

  // id = 1 for the components in the error test, 0 for the rest (suppressed).
  bool exclude_from_error_test(void* ida) {
    id_.reset(N_VNew_Serial(n_, context_.get()));
    if (!id_) return setup_failed(-1, "N_VNew_Serial failed");
    auto id = view_mutable(id_.get());
    id.setZero();
    id.head(index_ == 3 ? dof_ : 2 * dof_).setOnes();
    return check_setup(IDASetId(ida, id_.get()), "IDASetId") &&
           check_setup(IDASetSuppressAlg(ida, SUNTRUE), "IDASetSuppressAlg");
  }

  // The residual F(t, y, y'); with yp == nullptr it writes the derivative part alone (F with
  // y' = 0, negated: the y' that zeroes the differential rows) into `out`.
  int evaluate_residual(double t, N_Vector y_vector, N_Vector yp_vector, N_Vector out) noexcept {
    if (index_ == 0) {
      const int flag = evaluate_rhs(t, y_vector, out);
      if (flag != 0 || yp_vector == nullptr) return flag;
      view_mutable(out) = view(yp_vector) - view(out);
      return 0;
    }
    try {
      const auto y = view(y_vector);
      const int n = dof_, m = constraint_count_;
      const Problem& problem = *problem_;
      q_ = y.head(n);
      p_ = y.segment(n, n);
      const Vec v = MassOperator(problem).solve(q_, p_);
      if (const LagrangianSystem* general = problem.as_lagrangian()) {
        general->lagrangian_q(q_, v, force_);  // p' = L_q = T_q − ∇V on M(q)
      } else {
        problem.gradient(q_, force_);
        force_ = -force_;
      }
      if (problem.has(kForce)) {
        force_of(problem).force(q_, v, t, applied_);
        force_ += applied_;
      }
      constraints_->constraint_jacobian_at(t, q_, G_);
      force_ -= G_.transpose() * y.segment(2 * n, m);
      rate_.resize(2 * n);
      rate_.head(n) = v;
      if (index_ == 2) {
        rate_.head(n) -= MassOperator(problem).solve(q_, G_.transpose() * y.tail(m));
      }
      rate_.tail(n) = force_;
      if (!rate_.allFinite()) return 1;
      auto r = view_mutable(out);
      r.setZero();
      if (yp_vector == nullptr) {
        r.head(2 * n) = rate_;
        return 0;
      }
      r.head(2 * n) = view(yp_vector).head(2 * n) - rate_;
      constraints_->constraint_at(t, q_, g_);
      if (index_ == 3) {
        r.tail(m) = g_;
      } else {
        // dg/dt = G v + ∂g/∂t (rheonomic constraints; zero otherwise).
        constraints_->constraint_time_terms(t, q_, v, g_time_, a_time_);
        r.segment(2 * n, m) = G_ * v + g_time_;
        r.tail(m) = g_;
      }
      return r.allFinite() ? 0 : 1;
    } catch (const std::exception& error) {
      callback_error_ = error.what();
      return -1;
    }
  }

  static int residual(sunrealtype t, N_Vector y, N_Vector yp, N_Vector r, void* self) {
    return static_cast<Ida*>(self)->evaluate_residual(t, y, yp, r);
  }

  static int jacobian(sunrealtype t, sunrealtype c_j, N_Vector y, N_Vector, N_Vector,
                      SUNMatrix matrix, void* self, N_Vector, N_Vector, N_Vector) {
    auto& ida = *static_cast<Ida*>(self);
    if (const int flag = ida.evaluate_jacobian(t, y); flag != 0) return flag;
    fill_dense(ida.jacobian_, -1.0, c_j, matrix);
    return 0;
  }

  void update_counters() {
    void* ida = memory_.get();
    long steps = 0, residual_evals = 0, residual_evals_ls = 0, jacobian_evals = 0, newton_iters = 0,
         error_test_fails = 0, solve_fails = 0;
    IDAGetNumSteps(ida, &steps);
    IDAGetNumResEvals(ida, &residual_evals);
    IDAGetNumLinResEvals(ida, &residual_evals_ls);
    IDAGetNumJacEvals(ida, &jacobian_evals);
    IDAGetNumNonlinSolvIters(ida, &newton_iters);
    IDAGetNumErrTestFails(ida, &error_test_fails);
    IDAGetNumStepSolveFails(ida, &solve_fails);
    counters_.steps = steps;
    // Each residual evaluation is one evaluation of f.
    counters_.force_evals = residual_evals + residual_evals_ls + extra_rhs_evals_;
    counters_.hessian_evals = analytic_jacobian_ ? jacobian_evals : 0;
    counters_.newton_iters = newton_iters;
    counters_.linear_solves = newton_iters;  // direct solver: one solve per Newton iteration
    counters_.rejected = error_test_fails + solve_fails;
  }

  int max_order_;
  int index_;  // 0: the ODE residual; 2 or 3: the constrained DAE of that index
  int max_nonlin_iters_;
  double nonlin_conv_coef_;
  // Absolute tolerance of λ (and μ) in the Newton convergence test when given; otherwise atol,
  // at index 2 with the cap of evaluate_step_scaled_weights.
  std::optional<double> multiplier_atol_;
  double first_step_ = 0;        // index 2 with step-scaled weights: the step IDA starts with
  bool index3_started_ = false;  // index 3: the first step has been chosen
  int constraint_count_ = 0;
  const HolonomicConstraints* constraints_ = nullptr;  // the problem's, set by reset (index 2, 3)
  bool analytic_jacobian_ = false;
  Vec q_, p_, force_, applied_, rate_, g_, g_time_, a_time_;
  SparseMatrix G_;
  VectorPtr yp_;
  VectorPtr id_;
  MatrixPtr matrix_;
  LinearSolverPtr linear_solver_;
  MemoryPtr<IdaDeleter> memory_;
};

// ---------------------------------------------------------------------------------------------
// ARKODE with a built-in embedded explicit Butcher table (ARKODE user guide v5.4, §2.2, §8.1).
// SUNDIALS 6.4's ERKStep reuses the last stage derivative as f(t_{n+1}, y_{n+1}) whenever
// c_s = 1, also for tables that are not first-same-as-last (llnl/sundials issue #311): Verner
// 8-5-6 drops to third order, Fehlberg 13-7-8 to seventh. So ERKStep is used only for FSAL
// tables, where the reuse is right and saves one f per step; the others run through ARKStep in
// explicit-only mode, which evaluates every stage.

struct ErkTable {
  ARKODE_ERKTableID id;
  int order;
};
const std::map<std::string, ErkTable>& erk_tables() {
  static const std::map<std::string, ErkTable> tables = {
      {"dormand_prince", {ARKODE_DORMAND_PRINCE_7_4_5, 5}},
      {"verner_8_5_6", {ARKODE_VERNER_8_5_6, 6}},
      {"fehlberg_13_7_8", {ARKODE_FEHLBERG_13_7_8, 8}},
  };
  return tables;
}

// First same as last: the last stage is evaluated at the new solution (last row of A = b).
bool is_fsal(ARKODE_ERKTableID id) {
  const ARKodeButcherTable table = ARKodeButcherTable_LoadERK(id);
  if (table == nullptr) return false;
  const int last = table->stages - 1;
  bool fsal = table->c[last] == 1.0;
  for (int j = 0; j < table->stages; ++j) fsal = fsal && table->A[last][j] == table->b[j];
  ARKodeButcherTable_Free(table);
  return fsal;
}

// The calls that differ between ERKStep and ARKStep, so one wrapper drives either.
struct ArkodeApi {
  const char* name;
  void* (*create)(ARKRhsFn f, sunrealtype t0, N_Vector y0, SUNContext context);
  int (*set_error_handler)(void* memory, ARKErrHandlerFn handler, void* data);
  int (*set_user_data)(void* memory, void* data);
  int (*tolerances)(void* memory, sunrealtype rtol, sunrealtype atol);
  int (*set_table)(void* memory, ARKODE_ERKTableID id);
  int (*set_stop_time)(void* memory, sunrealtype t_stop);
  int (*evolve)(void* memory, sunrealtype t_out, N_Vector y, sunrealtype* t_returned, int task);
  int (*steps)(void* memory, long* count);
  int (*rhs_evals)(void* memory, long* count);
  int (*error_test_fails)(void* memory, long* count);
  char* (*flag_name)(long flag);
  void (*free)(void** memory);
};

const ArkodeApi kErkStep = {
    "ERKStep",
    &ERKStepCreate,
    &ERKStepSetErrHandlerFn,
    &ERKStepSetUserData,
    &ERKStepSStolerances,
    &ERKStepSetTableNum,
    &ERKStepSetStopTime,
    &ERKStepEvolve,
    &ERKStepGetNumSteps,
    &ERKStepGetNumRhsEvals,
    &ERKStepGetNumErrTestFails,
    &ERKStepGetReturnFlagName,
    &ERKStepFree,
};

const ArkodeApi kArkStepExplicit = {
    "ARKStep",
    [](ARKRhsFn f, sunrealtype t0, N_Vector y0, SUNContext context) {
      return ARKStepCreate(f, nullptr, t0, y0, context);
    },
    &ARKStepSetErrHandlerFn,
    &ARKStepSetUserData,
    &ARKStepSStolerances,
    [](void* memory, ARKODE_ERKTableID id) {
      return ARKStepSetTableNum(memory, ARKODE_DIRK_NONE, id);
    },
    &ARKStepSetStopTime,
    &ARKStepEvolve,
    &ARKStepGetNumSteps,
    [](void* memory, long* count) {
      long implicit_evals = 0;
      return ARKStepGetNumRhsEvals(memory, count, &implicit_evals);
    },
    &ARKStepGetNumErrTestFails,
    &ARKStepGetReturnFlagName,
    &ARKStepFree,
};

struct ArkodeDeleter {
  const ArkodeApi* api = nullptr;
  void operator()(void* memory) const { api->free(&memory); }
};

class ArkodeErk final : public SundialsIntegrator {
 public:
  ArkodeErk(const AdaptiveSettings& settings, std::string table)
      : SundialsIntegrator(settings, "arkode"),
        table_name_(std::move(table)),
        api_(is_fsal(erk_tables().at(table_name_).id) ? &kErkStep : &kArkStepExplicit) {}

  MethodInfo info() const override {
    // kGeneralLagrangian: like CVODE, ARKODE sees only first_order_rhs (Hamilton's equations of a
    // non-separable problem's L).
    return {"arkode_erk", erk_tables().at(table_name_).order,
            kExplicit | kAdaptive | kFirstOrderCapable | kGeneralLagrangian,
            fmt::format("SUNDIALS ARKODE {}, table {} (ARKODE user guide v5.4.1, §8.1)", api_->name,
                        table_name_)};
  }

  void reset(const Problem& problem, const State& state, double) override {
    memory_.reset();
    if (!begin_reset(problem, state)) return;
    memory_ = MemoryPtr<ArkodeDeleter>(api_->create(&rhs, state.t, y_.get(), context_.get()),
                                       ArkodeDeleter{api_});
    if (!memory_) {
      setup_failed(-1, "ARKODE create failed");
      return;
    }
    void* ark = memory_.get();
    if (!check_setup(api_->set_error_handler(ark, &record_message, this), "SetErrHandlerFn") ||
        !check_setup(api_->set_user_data(ark, this), "SetUserData") ||
        !check_setup(api_->tolerances(ark, settings_.rtol, settings_.atol), "SStolerances")) {
      return;
    }
    check_setup(api_->set_table(ark, erk_tables().at(table_name_).id), "SetTableNum");
  }

  StepStatus adaptive_step(const Problem& problem, State& state, double t_stop) override {
    StepStatus status;
    if (!ready_to_step(problem, state, t_stop, status)) return status;
    void* ark = memory_.get();
    int flag = api_->set_stop_time(ark, t_stop);
    double t_returned = t_;
    if (flag >= 0) flag = api_->evolve(ark, t_stop, y_.get(), &t_returned, ARK_ONE_STEP);
    update_counters();
    if (flag < 0) return library_failure(flag, api_->flag_name);
    publish(y_.get(), t_returned, t_stop, flag == ARK_TSTOP_RETURN || t_returned >= t_stop, state);
    return StepStatus::success();
  }

 private:
  static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* self) {
    return static_cast<ArkodeErk*>(self)->evaluate_rhs(t, y, ydot);
  }

  void update_counters() {
    void* ark = memory_.get();
    long steps = 0, rhs_evals = 0, error_test_fails = 0;
    api_->steps(ark, &steps);
    api_->rhs_evals(ark, &rhs_evals);
    api_->error_test_fails(ark, &error_test_fails);
    counters_.steps = steps;
    counters_.force_evals = rhs_evals;
    counters_.rejected = error_test_fails;
  }

  std::string table_name_;
  const ArkodeApi* api_;
  MemoryPtr<ArkodeDeleter> memory_{nullptr, ArkodeDeleter{api_}};
};

// The nonlinear solver's iterations per attempt (CVodeSetMaxNonlinIters, IDASetMaxNonlinIters),
// left out of the canonical spec at the library's default so committed runs keep their names. A
// step whose solves keep failing ends as the library's convergence failure (CV_CONV_FAILURE,
// IDA_CONV_FAIL) once the step size has been cut often enough.
long read_max_nonlin_iters(Params& params, long library_default) {
  const long value =
      params.integer("max_nonlin_iters", library_default,
                     "Newton iterations per nonlinear solve before the step counts as a "
                     "convergence failure (and is retried with a smaller step)",
                     1, 100);
  params.omit_default_from_canonical("max_nonlin_iters");
  return value;
}

std::unique_ptr<Integrator> make_cvode(Params& params, bool bdf) {
  const AdaptiveSettings settings = read_settings(params);
  const int limit = bdf ? 5 : 12;
  const auto max_order = static_cast<int>(
      params.integer("max_order", limit, "maximum order of the variable-order formulas", 1, limit));
  const std::string solver =
      params.choice("linear_solver", "dense", {"dense", "klu"},
                    "Newton linear solver: dense LU, or KLU sparse LU on the sparse Jacobian");
  const long setup_every = params.integer(
      "setup_every", 1,
      "Newton setup frequency: evaluate the Jacobian and factor I - gamma*J at most this many "
      "steps apart (1 = every step; 20 = CVODE's default modified Newton)",
      1, 1000);
  const double nonlin_conv_coef = params.real(
      "nonlin_conv_coef", 0.1,
      "Newton convergence test coefficient relative to the local error test (CVODE default 0.1)",
      Range::open_closed(0, 1));
  const long max_nonlin_iters = read_max_nonlin_iters(params, 3);
  return std::make_unique<Cvode>(
      bdf, settings, max_order, solver == "klu" ? LinearSolverKind::kKlu : LinearSolverKind::kDense,
      setup_every, nonlin_conv_coef, static_cast<int>(max_nonlin_iters));
}

}  // namespace

std::unique_ptr<Integrator> make_cvode_bdf(Params& params) { return make_cvode(params, true); }

std::unique_ptr<Integrator> make_cvode_adams(Params& params) { return make_cvode(params, false); }

std::unique_ptr<Integrator> make_ida(Params& params) {
  const AdaptiveSettings settings = read_settings(params);
  const auto max_order = static_cast<int>(
      params.integer("max_order", 5, "maximum order of the variable-order BDF formulas", 1, 5));
  const std::string index = params.choice(
      "index", "ode", {"ode", "2", "3"},
      "what IDA solves: the unconstrained first-order ODE, or on a constrained problem the DAE "
      "of index 3 (q, p, lambda; g = 0) or the stabilised index-2 GGL form (q, p, lambda, mu; "
      "G v = 0 and g = 0)");
  // Plain `ida` keeps its canonical spec (and the names of its committed runs).
  params.omit_default_from_canonical("index");
  const long max_nonlin_iters = read_max_nonlin_iters(params, 4);
  const double nonlin_conv_coef = params.real(
      "nonlin_conv_coef", 0.33,
      "Newton convergence test coefficient relative to the local error test (IDA default 0.33)",
      Range::open_closed(0, 1));
  params.omit_default_from_canonical("nonlin_conv_coef");
  const bool multiplier_atol_given = params.given("multiplier_atol");
  const double multiplier_atol = params.real(
      "multiplier_atol", settings.atol,
      "absolute tolerance of the multipliers (index 2 or 3), which only IDA's Newton "
      "convergence test weighs (default: atol, at index 2 capped where the multipliers' "
      "round-off, amplified by 1/h, would fail that test)",
      Range::at_least(0));
  // Given, it stays in the canonical spec even at the value of atol: at index 2 it then differs
  // from the default.
  if (!multiplier_atol_given) params.omit_default_from_canonical("multiplier_atol");
  return std::make_unique<Ida>(
      settings, max_order, index == "ode" ? 0 : std::stoi(index),
      static_cast<int>(max_nonlin_iters), nonlin_conv_coef,
      multiplier_atol_given ? std::optional<double>(multiplier_atol) : std::nullopt);
}

std::unique_ptr<Integrator> make_arkode_erk(Params& params) {
  const AdaptiveSettings settings = read_settings(params);
  std::vector<std::string> names;
  for (const auto& [name, table] : erk_tables()) names.push_back(name);
  const std::string table =
      params.choice("table", "dormand_prince", names, "embedded explicit Butcher table");
  return std::make_unique<ArkodeErk>(settings, table);
}

}  // namespace geomint
