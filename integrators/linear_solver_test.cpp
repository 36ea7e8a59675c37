// The Newton solver's linear solvers (integrators/newton.hpp LinearSolverKind; docs/METHODS.md
// "Scale"): every choice gives the same trajectory to the Newton tolerance, at unit and
// far-from-unit scales, the SPD safeguard works with each, modified Newton saves factorisations
// (and Hessian assemblies, with CG), bad values are named.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace linear_solver_test {
namespace {

const std::vector<std::string> kSolvers = {"ldlt", "ldlt_metis", "cholmod",
                                           "cg",   "cg_ichol",   "cg_amg"};

struct Trajectory {
  State state;
  Counters counters;
};

// `steps` steps of `method` on `problem_spec` at 20× the explicit limit 2/ω_max.
Trajectory integrate(const std::string& problem_spec, const std::string& method, int steps) {
  const auto problem = make_problem(problem_spec);
  const auto integrator = make_integrator(method);
  Trajectory out{problem->initial_state(), {}};
  const double h = 20 * 2 / problem->omega_max(out.state.q);
  integrator->reset(*problem, out.state, h);
  for (int k = 0; k < steps; ++k) {
    const StepStatus status = integrator->step(*problem, out.state, h);
    EXPECT_TRUE(status.ok) << method << " step " << k << ": " << status.message;
    if (!status.ok) break;
  }
  out.counters = integrator->counters();
  return out;
}

double relative_difference(const Vec& a, const Vec& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / b.lpNorm<Eigen::Infinity>();
}

class SameTrajectory : public ::testing::TestWithParam<std::string> {};

TEST_P(SameTrajectory, EverySolverMatchesLdltToTheNewtonTolerance) {
  // A free, spinning bar (momenta are exact invariants of hp, so a solver that is off shows
  // there too) at unit scale and at lengths ×1e3, stiffness ×1e9, density ×1e4.
  const std::vector<std::string> bars = {
      "elastic_bar:nx=6,ny=2,nz=2,clamp=none",
      "elastic_bar:nx=6,ny=2,nz=2,clamp=none,length=1000,width=200,height=200,young=1e14,"
      "density=1e7"};
  for (const std::string& bar : bars) {
    const std::string base = GetParam() + (GetParam().find(':') == std::string::npos ? ":" : ",");
    const Trajectory reference = integrate(bar, base + "linear_solver=ldlt", 10);
    for (const std::string& solver : kSolvers) {
      for (const char* modified : {"false", "true"}) {
        const std::string method =
            base + "linear_solver=" + solver + ",modified_newton=" + modified;
        const Trajectory other = integrate(bar, method, 10);
        // Ten steps, each solved to a relative residual 1e-12 (the conditioning at 20× the
        // explicit limit amplifies it into the state).
        EXPECT_LE(relative_difference(other.state.q, reference.state.q), 1e-9) << bar << method;
        EXPECT_LE(relative_difference(other.state.p, reference.state.p), 1e-9) << bar << method;
        EXPECT_GT(other.counters.factorizations, 0) << method;
        // Modified Newton keeps the Newton matrix (and, for CG, its preconditioner) across
        // iterations and steps; cg_amg reuses its multigrid set-up across them, modified or not.
        if (std::string(modified) == "true" || solver == "cg_amg") {
          EXPECT_LT(other.counters.factorizations, other.counters.newton_iters) << method;
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(ImplicitMethods, SameTrajectory,
                         ::testing::Values("implicit_euler", "hp", "hp:solver=newton",
                                           "del:rule=midpoint", "implicit_midpoint"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name;
                           for (char c : info.param)
                             name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

// E(x) = Σ −cos xᵢ + ½c Σ (xᵢ − xᵢ₊₁)², with the identity as SPD shift. From xᵢ = 2 the Hessian
// is negative definite, so with the safeguard every solver must detect it (LDLT pivots, CHOLMOD's
// NumericalIssue, CG's curvature test) and shift; the minimiser is x = 0.
NewtonSystem cosine_chain(int n, double c) {
  NewtonSystem system;
  system.symmetric = true;
  system.objective = [c](const Vec& x) {
    double e = 0;
    for (int i = 0; i < x.size(); ++i) e -= std::cos(x[i]);
    for (int i = 0; i + 1 < x.size(); ++i) e += 0.5 * c * (x[i] - x[i + 1]) * (x[i] - x[i + 1]);
    return e;
  };
  system.residual = [c](const Vec& x, Vec& r) {
    r = x.array().sin();
    for (int i = 0; i + 1 < x.size(); ++i) {
      r[i] += c * (x[i] - x[i + 1]);
      r[i + 1] -= c * (x[i] - x[i + 1]);
    }
  };
  system.jacobian = [c](const Vec& x, SparseMatrix& J) {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < x.size(); ++i) {
      const double coupling = (i > 0 ? c : 0.0) + (i + 1 < x.size() ? c : 0.0);
      t.emplace_back(i, i, std::cos(x[i]) + coupling);
      if (i + 1 < x.size()) {
        t.emplace_back(i, i + 1, -c);
        t.emplace_back(i + 1, i, -c);
      }
    }
    J.resize(x.size(), x.size());
    J.setFromTriplets(t.begin(), t.end());
  };
  SparseMatrix identity(n, n);
  identity.setIdentity();
  system.spd_shift = identity;
  return system;
}

TEST(LinearSolvers, SpdSafeguardShiftsWithEverySolver) {
  for (LinearSolverKind kind :
       {LinearSolverKind::kLdlt, LinearSolverKind::kLdltMetis, LinearSolverKind::kCholmod,
        LinearSolverKind::kCg, LinearSolverKind::kCgIchol, LinearSolverKind::kCgAmg}) {
    NewtonOptions options;
    options.linear.kind = kind;
    Vec x = Vec::Constant(8, 2.0);
    const NewtonResult result = NewtonSolver(options).solve(cosine_chain(8, 0.5), x, 1.0);
    ASSERT_TRUE(result.converged) << linear_solver_name(kind) << ": " << describe(result);
    EXPECT_LE(x.lpNorm<Eigen::Infinity>(), 1e-10) << linear_solver_name(kind);
    EXPECT_GE(result.shifted_iterations, 1) << linear_solver_name(kind);
  }
}

TEST(LinearSolvers, IndefiniteMatrixWithoutSafeguardFallsBackToLdlt) {
  // Plain Newton on R = ∇E (no objective, hence no safeguard) from xᵢ = 2.5 runs to the maximum
  // xᵢ = π, where J = −I + c·(graph Laplacian) is negative definite: CHOLMOD and CG cannot
  // factorise or iterate on it; they fall back to LDLT and reach the same root as LDLT does.
  Vec reference;
  for (LinearSolverKind kind : {LinearSolverKind::kLdlt, LinearSolverKind::kCholmod,
                                LinearSolverKind::kCg, LinearSolverKind::kCgAmg}) {
    NewtonSystem system = cosine_chain(6, 0.1);
    system.objective = nullptr;
    NewtonOptions options;
    options.linear.kind = kind;
    Vec x = Vec::Constant(6, 2.5);
    const NewtonResult result = NewtonSolver(options).solve(system, x, 1.0);
    ASSERT_TRUE(result.converged) << linear_solver_name(kind) << ": " << describe(result);
    if (kind != LinearSolverKind::kLdlt) {  // the LDLT fallback is an extra factorisation
      EXPECT_GT(result.factorizations, result.iterations) << linear_solver_name(kind);
    }
    if (reference.size() == 0) reference = x;
    EXPECT_LE((x - reference).lpNorm<Eigen::Infinity>(), 1e-10) << linear_solver_name(kind);
  }
}

// R(x) = A x − b on a 31 × 31 grid (961 unknowns, not a multiple of 3: scalar AMG), with
// A = M + a·Lₓ + Lᵧ, M = I, L the 1-D second-difference operators scaled by 10⁴: isotropic for
// a = 1; for a = 10⁴ the x couplings dominate, which an isotropic hierarchy does not coarsen along,
// so CG needs far more iterations with it (the textbook case for rebuilding AMG).
NewtonSystem anisotropic_grid(const double& anisotropy) {
  constexpr int kSide = 31;
  NewtonSystem system;
  system.symmetric = true;
  auto matrix = [&anisotropy] {
    std::vector<Eigen::Triplet<double>> t;
    const auto index = [](int i, int j) { return i * kSide + j; };
    for (int i = 0; i < kSide; ++i) {
      for (int j = 0; j < kSide; ++j) {
        const double ax = 1e4 * anisotropy, ay = 1e4;
        t.emplace_back(index(i, j), index(i, j), 1.0 + 2 * ax + 2 * ay);
        if (i + 1 < kSide) {
          t.emplace_back(index(i, j), index(i + 1, j), -ax);
          t.emplace_back(index(i + 1, j), index(i, j), -ax);
        }
        if (j + 1 < kSide) {
          t.emplace_back(index(i, j), index(i, j + 1), -ay);
          t.emplace_back(index(i, j + 1), index(i, j), -ay);
        }
      }
    }
    SparseMatrix A(kSide * kSide, kSide * kSide);
    A.setFromTriplets(t.begin(), t.end());
    return A;
  };
  system.residual = [matrix](const Vec& x, Vec& r) { r = matrix() * x - Vec::Ones(x.size()); };
  system.jacobian = [matrix](const Vec&, SparseMatrix& J) { J = matrix(); };
  return system;
}

TEST(LinearSolvers, AmgSetUpIsReusedUntilCgSlowsDown) {
  // Three solves with one solver (as across steps): isotropic, then twice strongly anisotropic.
  // The first anisotropic Newton iteration runs on the isotropic set-up and needs many more CG
  // iterations, which marks the set-up worn out; the next Jacobian gets a new one.
  const auto three_solves = [](double refresh_growth) {
    NewtonOptions options;
    options.linear.kind = LinearSolverKind::kCgAmg;
    options.linear.amg_refresh_growth = refresh_growth;
    NewtonSolver solver(options);
    double anisotropy = 1.0;
    const NewtonSystem system = anisotropic_grid(anisotropy);
    std::vector<NewtonResult> results;
    for (double a : {1.0, 1e4, 1e4}) {
      anisotropy = a;
      Vec x = Vec::Zero(31 * 31);
      results.push_back(solver.solve(system, x, 1.0));
      EXPECT_TRUE(results.back().converged) << describe(results.back());
      EXPECT_EQ(results.back().factorizations, results.back().amg_setups);
    }
    return results;
  };
  const auto setups = [](const std::vector<NewtonResult>& results) {
    std::vector<int> out;
    for (const NewtonResult& r : results) out.push_back(r.amg_setups);
    return out;
  };
  // Default rule: one set-up for the first solve (reused by its later iterations); the second
  // solve's first iteration on the old set-up is slow, its second iteration gets a new set-up,
  // which the third solve reuses.
  const std::vector<NewtonResult> refreshed = three_solves(2.0);
  EXPECT_EQ(setups(refreshed), (std::vector<int>{1, 1, 0}));
  EXPECT_GE(refreshed[0].iterations, 2);
  EXPECT_GE(refreshed[1].iterations, 2);
  // Never refreshed (an unbounded growth allowance): the first set-up serves all three solves,
  // and the last one pays for it in CG iterations.
  const std::vector<NewtonResult> kept = three_solves(1e9);
  EXPECT_EQ(setups(kept), (std::vector<int>{1, 0, 0}));
  EXPECT_GT(kept[2].cg_iterations, 2 * refreshed[2].cg_iterations + kAmgRefreshSlack);
  // growth 0: a set-up for every Jacobian.
  for (const NewtonResult& r : three_solves(0.0)) EXPECT_EQ(r.amg_setups, r.iterations);
}

// Modified Newton with CG (LinearSolverOptions::modified_newton): the held Newton matrix serves
// later iterations and solves (no Jacobian evaluation) until an iteration on it contracts ‖R‖ by
// less than kModifiedNewtonContraction; a changed operator must bring a new Jacobian. The grid
// scaled by 1, 1e-150 and 1e+150 (R and J together), solved four times as across steps: the
// isotropic operator twice, then twice with the x couplings 1.6 times stronger. On the isotropic
// matrix that iteration still converges, but slowly (without the refresh rule it is kept, and the
// third solve evaluates no Jacobian).
TEST(LinearSolvers, CgModifiedNewtonKeepsTheMatrixUntilTheOperatorChanges) {
  for (double scale : {1.0, 1e-150, 1e150}) {
    for (LinearSolverKind kind : {LinearSolverKind::kCg, LinearSolverKind::kCgIchol}) {
      for (bool modified : {true, false}) {
        double anisotropy = 1.0;
        const NewtonSystem grid = anisotropic_grid(anisotropy);
        int jacobians = 0;
        NewtonSystem system = grid;
        system.residual = [&](const Vec& x, Vec& r) {
          grid.residual(x, r);
          r *= scale;
        };
        system.jacobian = [&](const Vec& x, SparseMatrix& J) {
          ++jacobians;
          grid.jacobian(x, J);
          J *= scale;
        };
        // An inner-term scale far above the residual's (a stiff term): it sets the threshold, and
        // a solve that starts on the held matrix must keep it (else it asks for a residual ~3 500
        // times below the round-off of R's terms).
        system.inner_term_scale = [scale] { return 1e6 * scale; };
        NewtonOptions options;
        options.linear.kind = kind;
        options.linear.modified_newton = modified;
        NewtonSolver solver(options);
        std::vector<int> jacobians_per_solve;
        std::vector<double> thresholds;
        for (double a : {1.0, 1.0, 1.6, 1.6}) {
          anisotropy = a;
          jacobians = 0;
          Vec x = Vec::Zero(31 * 31);
          const NewtonResult result = solver.solve(system, x, scale);
          ASSERT_TRUE(result.converged) << describe(result) << " scale " << scale;
          // The root of the current operator, whatever matrix the directions came from.
          Vec r;
          system.residual(x, r);
          EXPECT_LE(robust_norm(r), result.threshold) << scale;
          jacobians_per_solve.push_back(jacobians);
          thresholds.push_back(result.threshold);
        }
        const std::string label =
            std::string(linear_solver_name(kind)) + (modified ? " modified" : " full") + " scale ";
        if (modified) {
          // One Jacobian for the first solve, none for the repeated one (it starts on the held
          // matrix, and its threshold is the first solve's); the anisotropic operator gets a
          // Jacobian of its own, which its repetition reuses.
          EXPECT_EQ(jacobians_per_solve, (std::vector<int>{1, 0, 1, 0})) << label << scale;
          EXPECT_EQ(thresholds[1], thresholds[0]) << label << scale;
          EXPECT_EQ(thresholds[3], thresholds[2]) << label << scale;
        } else {
          for (int count : jacobians_per_solve) EXPECT_GE(count, 1) << label << scale;
        }
        EXPECT_GT(thresholds[0], 1e3 * 1e-12 * scale) << label << scale;  // set by the inner term
      }
    }
  }
}

// R(x) = A x − b with A = tridiag(−1, 2.01, −1) on 301 unknowns (condition number ~400), b of
// size `scale` (and x with it).
NewtonSystem linear_chain(double scale) {
  constexpr int kSize = 301;
  NewtonSystem system;
  system.symmetric = true;
  auto matrix = [] {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < kSize; ++i) {
      t.emplace_back(i, i, 2.01);
      if (i + 1 < kSize) {
        t.emplace_back(i, i + 1, -1.0);
        t.emplace_back(i + 1, i, -1.0);
      }
    }
    SparseMatrix A(kSize, kSize);
    A.setFromTriplets(t.begin(), t.end());
    return A;
  };
  Vec b(kSize);
  for (int i = 0; i < kSize; ++i) b[i] = scale * std::sin(0.37 * i + 1.0);
  system.residual = [matrix, b](const Vec& x, Vec& r) { r = matrix() * x - b; };
  system.jacobian = [matrix](const Vec&, SparseMatrix& J) { J = matrix(); };
  return system;
}

// Inexact Newton (integrators/newton.cpp, the Eisenstat–Walker forcing terms): on a linear R the
// first step's linear model is exact, so the second CG solve is asked for the whole remaining
// reduction and Newton ends after two iterations (one with cg_ichol, whose incomplete factor of
// a tridiagonal matrix is exact). With the constant forcing 1e-3 it took one iteration per three
// decades of ‖R‖ (four or five here, down to 1e-12‖b‖). At scales 1e-150 and 1e+150 too: the
// forcing is relative.
TEST(LinearSolvers, InexactNewtonSolvesALinearSystemInTwoIterations) {
  for (double scale : {1.0, 1e-150, 1e150}) {
    for (LinearSolverKind kind :
         {LinearSolverKind::kCg, LinearSolverKind::kCgIchol, LinearSolverKind::kCgAmg}) {
      const NewtonSystem system = linear_chain(scale);
      NewtonOptions options;
      options.linear.kind = kind;
      Vec x = Vec::Zero(301);
      Vec r0;
      system.residual(x, r0);
      const NewtonResult result = NewtonSolver(options).solve(system, x, robust_norm(r0));
      ASSERT_TRUE(result.converged) << linear_solver_name(kind) << " " << describe(result);
      EXPECT_LE(result.iterations, 2) << linear_solver_name(kind) << " at scale " << scale;
    }
  }
}

// CG multiplies by both triangles: a symmetric system that stores only its lower triangle (all
// NewtonSystem::symmetric promises to read) is mirrored first, and gives LDLT's root.
TEST(LinearSolvers, CgReadsTheLowerTriangleOfASymmetricSystem) {
  for (LinearSolverKind kind : {LinearSolverKind::kLdlt, LinearSolverKind::kCg,
                                LinearSolverKind::kCgIchol, LinearSolverKind::kCgAmg}) {
    NewtonSystem system = linear_chain(1.0);
    const auto full = system.jacobian;
    system.jacobian = [full](const Vec& x, SparseMatrix& J) {
      SparseMatrix whole;
      full(x, whole);
      J = whole.triangularView<Eigen::Lower>();
    };
    NewtonOptions options;
    options.linear.kind = kind;
    Vec x = Vec::Zero(301);
    Vec r;
    system.residual(x, r);
    const double size = robust_norm(r);
    const NewtonResult result = NewtonSolver(options).solve(system, x, size);
    ASSERT_TRUE(result.converged) << linear_solver_name(kind) << " " << describe(result);
    system.residual(x, r);
    EXPECT_LE(r.norm(), 1e-12 * size) << linear_solver_name(kind);
    EXPECT_LE(result.iterations, 2) << linear_solver_name(kind);  // exact directions
    // and no LDLT fallback (an extra factorisation), which a CG on the wrong operator ends in
    EXPECT_LE(result.factorizations, result.iterations) << linear_solver_name(kind);
  }
}

TEST(LinearSolvers, AutoPicksByTheNumberOfUnknowns) {
  EXPECT_EQ(resolve_linear_solver(LinearSolverKind::kAuto, kAutoIterativeFrom - 1),
            LinearSolverKind::kLdlt);
  EXPECT_EQ(resolve_linear_solver(LinearSolverKind::kAuto, kAutoIterativeFrom),
            LinearSolverKind::kCg);
  EXPECT_EQ(resolve_linear_solver(LinearSolverKind::kCg, 3), LinearSolverKind::kCg);
  // cg at every larger size: cg_amg measured no faster up to 10⁶ tets (integrators/newton.cpp,
  // docs/PERF.md "Implicit step").
  EXPECT_EQ(resolve_linear_solver(LinearSolverKind::kAuto, 200000), LinearSolverKind::kCg);
  EXPECT_EQ(resolve_linear_solver(LinearSolverKind::kAuto, 3000000), LinearSolverKind::kCg);
}

TEST(LinearSolvers, OptionIsLeftOutOfTheCanonicalSpecAtItsDefault) {
  EXPECT_EQ(make_integrator("implicit_euler")->spec(), "implicit_euler:max_iter=50,tol=1e-12");
  EXPECT_EQ(make_integrator("implicit_euler:linear_solver=auto,modified_newton=false")->spec(),
            "implicit_euler:max_iter=50,tol=1e-12");
  EXPECT_EQ(make_integrator("implicit_euler:linear_solver=cg,modified_newton=true")->spec(),
            "implicit_euler:linear_solver=cg,max_iter=50,modified_newton=true,tol=1e-12");
}

TEST(LinearSolvers, BadValueIsAnInputErrorNamingTheAllowedValues) {
  for (const char* method :
       {"implicit_euler", "hp", "del", "newmark", "implicit_midpoint", "gauss", "lobatto3ab"}) {
    try {
      make_integrator(std::string(method) + ":linear_solver=lu");
      ADD_FAILURE() << method << " accepted linear_solver=lu";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("linear_solver"), std::string::npos) << message;
      EXPECT_NE(message.find("auto, ldlt, ldlt_metis, cholmod, cg, cg_ichol, cg_amg"),
                std::string::npos)
          << message;
    }
  }
}

}  // namespace
}  // namespace linear_solver_test
}  // namespace geomint
