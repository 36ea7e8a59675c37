// Registry-driven checks of the general Lagrangian kind (problems/lagrangian.hpp): every
// primitive and assembled derivative against central finite differences, the Legendre identities,
// energy along an accurate trajectory, and polar Kepler against Cartesian Kepler.
#include "problems/lagrangian.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "problems/problem.hpp"

namespace geomint {
namespace lagrangian_test {
namespace {

double inf_norm(const Eigen::MatrixXd& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

std::vector<std::string> general_specs() {
  std::vector<std::string> specs;
  for (const auto& spec : problem_test_specs()) {
    if (make_problem(spec)->kind() == ProblemKind::kLagrangian) specs.push_back(spec);
  }
  return specs;
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string out;
  for (char c : info.param) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

// Central-difference Jacobian of a vector function (columns = ∂f/∂x_j), step relative to |x_j| or
// to the component's typical size `scale[j]` (its units: an electron's x ~ 1e-5 m and p ~ 1e-24
// kg m/s, where a unit floor would step across the whole orbit or swamp p).
Eigen::MatrixXd difference_jacobian(const std::function<Vec(const Vec&)>& f, const Vec& x,
                                    const Vec& scale) {
  const Vec f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (int j = 0; j < x.size(); ++j) {
    const double delta = 1e-6 * std::max(scale[j], std::abs(x[j]));
    Vec plus = x, minus = x;
    plus[j] += delta;
    minus[j] -= delta;
    J.col(j) = (f(plus) - f(minus)) / (2 * delta);
  }
  return J;
}

// Central differences have truncation ~δ² and rounding ~ε/δ ≈ 1e-10 relative: 1e-7 leaves room
// and still catches a wrong factor or sign (which is O(1) of the entry).
// `floor`: an absolute tolerance below which the differences cannot resolve (see
// scalar_difference_floor).
void expect_close(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
                  const std::string& what, double floor = 0) {
  const double scale = std::max({inf_norm(analytic), inf_norm(numeric), 1e-300});
  EXPECT_LE(inf_norm(analytic - numeric), std::max(1e-7 * scale, floor))
      << what << "\nanalytic\n"
      << analytic << "\nfinite differences\n"
      << numeric;
}

// The rounding floor of difference_jacobian on a scalar f at x: the round-off of f's value, ε|f|,
// over the smallest step, with a margin of 100. It matters where f carries a term that does not
// depend on the variable differenced and dwarfs the one that does: L(q, v) and H(q, p) in v or p
// hold V(q), which on andrews (a stiff spring beside inertias of 1e-5 kg m²) is 10⁴ times the
// kinetic energy of the samples, so ∂/∂v cannot resolve 1e-7 of L_v = M v there.
double scalar_difference_floor(double value, const Vec& x, const Vec& scale) {
  double smallest_step = std::numeric_limits<double>::infinity();
  for (int j = 0; j < x.size(); ++j) {
    smallest_step = std::min(smallest_step, 1e-6 * std::max(scale[j], std::abs(x[j])));
  }
  return 100 * std::numeric_limits<double>::epsilon() * std::abs(value) / smallest_step;
}

class GeneralProblem : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    problem_ = make_problem(GetParam());
    ASSERT_NE(problem_->as_lagrangian(), nullptr) << "is_non_separable needs the LagrangianSystem";
  }
  const LagrangianSystem& system() const { return *problem_->as_lagrangian(); }
  // States the checks probe: the start and two nearby ones, each with a velocity that makes
  // every v-dependent term non-zero (the double pendulum starts from rest). Offsets and
  // velocities are in the problem's own length and speed (an electron's orbit is 6 µm across at
  // 10⁶ m/s: unit offsets would put qA(x) 10¹⁰ times above m v and leave v = (p − qA)/m no digit).
  std::vector<std::pair<Vec, Vec>> samples() const {
    const State start = problem_->initial_state();
    std::vector<std::pair<Vec, Vec>> out;
    const int n = problem_->dof();
    for (int k = 0; k < 3; ++k) {
      Vec q = start.q, v(n);
      for (int i = 0; i < n; ++i) {
        q[i] += 0.07 * k * (i + 1) * (i % 2 == 0 ? 1 : -1) * length();
        v[i] = (0.6 + 0.45 * i - 0.3 * k) * speed();
      }
      out.emplace_back(q, v);
    }
    return out;
  }
  // The size of the start's q and v (1 where it is zero: a pendulum at rest).
  double length() const {
    const double size = inf_norm(problem_->initial_state().q);
    return size > 0 ? size : 1.0;
  }
  double speed() const {
    const State start = problem_->initial_state();
    const double size = inf_norm(system().velocity(start.q, start.p));
    return size > 0 ? size : 1.0;
  }
  // Per-component scales for difference_jacobian: of q, of v, and of (q, p) at a sample.
  Vec q_scale() const { return Vec::Constant(problem_->dof(), length()); }
  Vec v_scale() const { return Vec::Constant(problem_->dof(), speed()); }
  Vec qp_scale(const Vec& p) const {
    const int n = problem_->dof();
    Vec scale(2 * n);
    scale << q_scale(), Vec::Constant(n, inf_norm(p) > 0 ? inf_norm(p) : 1.0);
    return scale;
  }
  std::unique_ptr<Problem> problem_;
};

TEST_P(GeneralProblem, MassIsSymmetricPositiveDefinite) {
  for (const auto& sample : samples()) {
    const Vec& q = sample.first;
    DenseMatrix M;
    system().mass_matrix(q, M);
    EXPECT_LE(inf_norm(M - M.transpose()), 0.0) << M;
    EXPECT_EQ(Eigen::LLT<DenseMatrix>(M).info(), Eigen::Success) << M;
  }
}

TEST_P(GeneralProblem, PrimitivesMatchFiniteDifferences) {
  const LagrangianSystem& L = system();
  // Named copies, not a structured binding: lambdas below capture them (clang 14 refuses that).
  for (const auto& sample : samples()) {
    const Vec& q = sample.first;
    const Vec& v = sample.second;
    const auto kinetic = [&](const Vec& x) {
      DenseMatrix M;
      L.mass_matrix(x, M);
      return Vec::Constant(1, 0.5 * v.dot(M * v));
    };
    Vec T_q;
    L.kinetic_gradient(q, v, T_q);
    expect_close(T_q.transpose(), difference_jacobian(kinetic, q, q_scale()), "T_q");
    DenseMatrix D;
    L.mass_velocity_jacobian(q, v, D);
    const auto mass_times_v = [&](const Vec& x) {
      DenseMatrix M;
      L.mass_matrix(x, M);
      return Vec(M * v);
    };
    expect_close(D, difference_jacobian(mass_times_v, q, q_scale()), "d(M v)/dq");
    DenseMatrix T_qq;
    L.kinetic_hessian(q, v, T_qq);
    const auto kinetic_gradient = [&](const Vec& x) {
      Vec g;
      L.kinetic_gradient(x, v, g);
      return g;
    };
    expect_close(T_qq, difference_jacobian(kinetic_gradient, q, q_scale()), "T_qq");
    DenseMatrix A;
    L.gyroscopic_jacobian(q, A);
    const auto gyroscopic = [&](const Vec& x) {
      Vec a;
      L.gyroscopic(x, a);
      return a;
    };
    expect_close(A, difference_jacobian(gyroscopic, q, q_scale()), "da/dq");
    DenseMatrix a_qq;
    L.gyroscopic_hessian(q, v, a_qq);
    const auto gyroscopic_gradient = [&](const Vec& x) {
      DenseMatrix Ax;
      L.gyroscopic_jacobian(x, Ax);
      return Vec(Ax.transpose() * v);
    };
    expect_close(a_qq, difference_jacobian(gyroscopic_gradient, q, q_scale()), "d²(a·v)/dq²");
    Vec g;
    L.gradient(q, g);
    const auto potential = [&](const Vec& x) { return Vec::Constant(1, L.potential(x)); };
    expect_close(g.transpose(), difference_jacobian(potential, q, q_scale()), "grad V");
    DenseMatrix K;
    L.potential_hessian(q, K);
    const auto gradient = [&](const Vec& x) {
      Vec gx;
      L.gradient(x, gx);
      return gx;
    };
    expect_close(K, difference_jacobian(gradient, q, q_scale()), "hess V");
  }
}

TEST_P(GeneralProblem, AssembledBlocksMatchFiniteDifferencesOfTheLagrangian) {
  const LagrangianSystem& L = system();
  // Named copies, not a structured binding: lambdas below capture them (clang 14 refuses that).
  for (const auto& sample : samples()) {
    const Vec& q = sample.first;
    const Vec& v = sample.second;
    Vec L_q;
    L.lagrangian_q(q, v, L_q);
    const auto lagrangian_at_q = [&](const Vec& x) { return Vec::Constant(1, L.lagrangian(x, v)); };
    expect_close(L_q.transpose(), difference_jacobian(lagrangian_at_q, q, q_scale()), "L_q");
    const auto lagrangian_at_v = [&](const Vec& w) { return Vec::Constant(1, L.lagrangian(q, w)); };
    expect_close(L.momentum(q, v).transpose(), difference_jacobian(lagrangian_at_v, v, v_scale()),
                 "L_v", scalar_difference_floor(L.lagrangian(q, v), v, v_scale()));
    DenseMatrix L_vq, L_qq, M;
    L.lagrangian_vq(q, v, L_vq);
    expect_close(L_vq,
                 difference_jacobian([&](const Vec& x) { return L.momentum(x, v); }, q, q_scale()),
                 "L_vq");
    L.mass_matrix(q, M);
    expect_close(M,
                 difference_jacobian([&](const Vec& w) { return L.momentum(q, w); }, v, v_scale()),
                 "L_vv");
    L.lagrangian_qq(q, v, L_qq);
    const auto lagrangian_q = [&](const Vec& x) {
      Vec g;
      L.lagrangian_q(x, v, g);
      return g;
    };
    expect_close(L_qq, difference_jacobian(lagrangian_q, q, q_scale()), "L_qq");
  }
}

TEST_P(GeneralProblem, HamiltonianViewIsTheLegendreTransform) {
  const LagrangianSystem& L = system();
  // Named copies, not a structured binding: lambdas below capture them (clang 14 refuses that).
  for (const auto& sample : samples()) {
    const Vec& q = sample.first;
    const Vec& v = sample.second;
    const Vec p = L.momentum(q, v);
    EXPECT_LE(inf_norm(L.velocity(q, p) - v), 1e-14 * inf_norm(v));
    // H = pᵀv − L at p = L_v.
    const double legendre = p.dot(v) - L.lagrangian(q, v);
    EXPECT_NEAR(L.hamiltonian(q, p), legendre, 1e-14 * (std::abs(p.dot(v)) + std::abs(legendre)));
    EXPECT_EQ(problem_->energy(q, p), L.hamiltonian(q, p));
    Vec H_q, H_p;
    L.hamiltonian_gradient(q, p, H_q, H_p);
    const auto h_of_q = [&](const Vec& x) { return Vec::Constant(1, L.hamiltonian(x, p)); };
    const auto h_of_p = [&](const Vec& y) { return Vec::Constant(1, L.hamiltonian(q, y)); };
    expect_close(H_q.transpose(), difference_jacobian(h_of_q, q, q_scale()), "H_q");
    const Vec p_scale = qp_scale(p).tail(p.size());
    expect_close(H_p.transpose(), difference_jacobian(h_of_p, p, p_scale), "H_p",
                 scalar_difference_floor(L.hamiltonian(q, p), p, p_scale));
    // Hamilton's vector field and its Jacobian, as the ODE solvers see them.
    Vec y(2 * q.size());
    y << q, p;
    Vec ydot;
    problem_->first_order_rhs(0.0, y, ydot);
    expect_close(ydot.head(q.size()), H_p, "q' = H_p");
    expect_close(ydot.tail(q.size()), -H_q, "p' = -H_q");
    SparseMatrix J;
    problem_->first_order_jacobian(0.0, y, J);
    const auto field = [&](const Vec& z) {
      Vec zdot;
      problem_->first_order_rhs(0.0, z, zdot);
      return zdot;
    };
    expect_close(Eigen::MatrixXd(J), difference_jacobian(field, y, qp_scale(p)),
                 "d(q', p')/d(q, p)");
  }
}

// Hamilton's equations through first_order_rhs keep H: classical RK4 at a step far inside its
// accuracy (error ~ (hω)⁴ per unit time) over a few time units.
TEST_P(GeneralProblem, EnergyIsKeptByAnAccurateTrajectory) {
  const State start = problem_->initial_state();
  const int n = problem_->dof();
  Vec y(2 * n);
  y << start.q, start.p;
  const double h = problem_->default_dt() / 10;
  // Two time units, or the default run where that is shorter (an electron gyrates 10¹¹ times a
  // second).
  const long steps = std::lround(std::min(2.0, problem_->default_t_end()) / h);
  const auto f = [&](const Vec& z) {
    Vec zdot;
    problem_->first_order_rhs(0.0, z, zdot);
    return zdot;
  };
  const double energy0 = problem_->energy(start.q, start.p);
  double worst = 0;
  for (long k = 0; k < steps; ++k) {
    const Vec k1 = f(y), k2 = f(y + h / 2 * k1), k3 = f(y + h / 2 * k2), k4 = f(y + h * k3);
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    worst = std::max(worst, std::abs(problem_->energy(y.head(n), y.tail(n)) - energy0));
  }
  // Relative to the sizes of kinetic and potential energy, not to 1 (an electron's is 1e-19 J).
  const double potential0 = problem_->potential(start.q);
  EXPECT_LE(worst, 1e-10 * (std::abs(energy0 - potential0) + std::abs(potential0)));
}

INSTANTIATE_TEST_SUITE_P(Registry, GeneralProblem, ::testing::ValuesIn(general_specs()), test_name);

TEST(GeneralProblems, RegistryHasThem) {
  EXPECT_GE(general_specs().size(), 4u);
  EXPECT_TRUE(make_problem("double_pendulum")->kind() == ProblemKind::kLagrangian);
  EXPECT_FALSE(make_problem("kepler")->kind() == ProblemKind::kLagrangian);
  EXPECT_EQ(make_problem("kepler")->as_lagrangian(), nullptr);
}

// Equal bobs and rods: the small-oscillation frequencies are ω² = (g/l)(2 ∓ √2)
// (../shared/MECHANICS.md §5); omega_max is the faster one, at non-unit m, l, g.
TEST(DoublePendulum, OmegaMaxIsTheFasterNormalMode) {
  const auto problem = make_problem("double_pendulum:m1=2,m2=2,l1=0.5,l2=0.5,g=3");
  const double expected = std::sqrt(3 / 0.5 * (2 + std::sqrt(2.0)));
  EXPECT_NEAR(problem->omega_max(problem->initial_state().q), expected, 1e-14 * expected);
}

// The polar exact solution is the Cartesian one mapped through (r cos φ, r sin φ), and p_φ is
// the angular momentum, over more than one turn (φ continuous).
TEST(KeplerPolar, ExactIsTheCartesianOrbitInPolarCoordinates) {
  for (const char* e : {"0.3", "0.6", "0.9"}) {
    const auto polar = make_problem(std::string("kepler:coordinates=polar,e=") + e);
    const auto cartesian = make_problem(std::string("kepler:e=") + e);
    double previous_phi = -1.0;
    for (int k = 0; k <= 50; ++k) {
      const double t = 0.37 * k;
      const State s = polar->exact(t);
      const State c = cartesian->exact(t);
      const double r = s.q[0], phi = s.q[1];
      Vec x(2), p(2);
      x << r * std::cos(phi), r * std::sin(phi);
      p << s.p[0] * std::cos(phi) - s.p[1] / r * std::sin(phi),
          s.p[0] * std::sin(phi) + s.p[1] / r * std::cos(phi);
      EXPECT_LE(inf_norm(x - c.q), 1e-14 * 4) << "e=" << e << " t=" << t;
      EXPECT_LE(inf_norm(p - c.p), 1e-14 * 4 * inf_norm(c.p)) << "e=" << e << " t=" << t;
      EXPECT_GT(phi, previous_phi) << "phi must increase continuously, t=" << t;
      previous_phi = phi;
      EXPECT_NEAR(s.p[1], (cartesian->angular_momentum(c.q, c.p))[0], 1e-14);
    }
  }
}

}  // namespace
}  // namespace lagrangian_test
}  // namespace geomint
