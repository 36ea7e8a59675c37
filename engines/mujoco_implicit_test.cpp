// Why MuJoCo 2.2.2's `implicit` integrator loses the double pendulum (docs/ENGINES.md): its step is
// one Newton step of implicit Euler in the velocity, the Coriolis and centrifugal forces' velocity
// Jacobian included, and that scheme, written out on the problem's own Lagrangian, gains the same
// energy: the growth is the scheme's, not the engine model's.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/LU>
#include <array>
#include <cstring>
#include <memory>

#include "engines/mujoco.hpp"
#include "engines/planar_chain.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"

namespace geomint::engines {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The adapter's own MJCF of `spec`, compiled by MuJoCo directly (no adapter between the test and
// mj_step).
struct RawModel {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  explicit RawModel(const std::string& xml) {
    auto vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    const char* name = "model.xml";
    EXPECT_EQ(mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())), 0);
    std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name)], xml.data(), xml.size());
    std::array<char, 1000> error{};
    model = mj_loadXML(name, vfs.get(), error.data(), static_cast<int>(error.size()));
    mj_deleteVFS(vfs.get());
    EXPECT_NE(model, nullptr) << error.data();
    data = mj_makeData(model);
  }
  ~RawModel() {
    mj_deleteData(data);
    mj_deleteModel(model);
  }
  RawModel(const RawModel&) = delete;
  RawModel& operator=(const RawModel&) = delete;

  int size() const { return model->nv; }
  // f = qfrc_smooth (gravity − Coriolis and centrifugal; nothing else is switched on) and M at
  // (qpos, qvel).
  Vec force(const Vec& qpos, const Vec& qvel, RowMajor* M = nullptr) {
    for (int i = 0; i < size(); ++i) data->qpos[i] = qpos[i], data->qvel[i] = qvel[i];
    mj_forward(model, data);
    if (M != nullptr) {
      M->resize(size(), size());
      mj_fullM(model, M->data(), data->qM);
    }
    return Eigen::Map<const Vec>(data->qfrc_smooth, size());
  }
};

std::string chain_xml(const std::string& spec, const std::string& integrator) {
  const auto problem = make_problem(spec);
  std::string why;
  const auto chain = planar_chain_of(*problem, why);
  EXPECT_TRUE(chain) << why;
  return MujocoChain(*chain, {integrator, false}).xml();
}

// ∂f/∂v by central differences of f (exact to O(ε²) on f, which is quadratic in v).
template <class Force>
DenseMatrix velocity_jacobian(Force force, const Vec& v) {
  const double eps = 1e-6;
  DenseMatrix J(v.size(), v.size());
  for (Eigen::Index j = 0; j < v.size(); ++j) {
    Vec up = v, down = v;
    up[j] += eps, down[j] -= eps;
    J.col(j) = (force(up) - force(down)) / (2 * eps);
  }
  return J;
}

TEST(MujocoImplicit, IsOneNewtonStepOfVelocityImplicitEulerWithTheCoriolisJacobian) {
  // A state with fast, crossing rates (relative joint angles and rates), so the Coriolis and
  // centrifugal forces are large.
  RawModel raw(chain_xml("double_pendulum", "implicit"));
  const double h = 1.0 / 60;
  raw.model->opt.timestep = h;
  Vec q(2), v(2);
  q << 0.7, -1.1;
  v << 1.3, -2.4;
  RowMajor M;
  const Vec f = raw.force(q, v, &M);
  const DenseMatrix D = velocity_jacobian([&](const Vec& w) { return raw.force(q, w); }, v);
  const Vec newton = v + h * (DenseMatrix(M) - h * D).lu().solve(f);
  const Vec euler = v + h * DenseMatrix(M).lu().solve(f);
  raw.force(q, v);
  mj_step(raw.model, raw.data);
  const Vec stepped = Eigen::Map<const Vec>(raw.data->qvel, 2);
  // v⁺ = v + h(M − hD)⁻¹f with D = ∂f/∂v, then q⁺ = q + hv⁺ (mj_implicit, mj_advance).
  EXPECT_LT((stepped - newton).norm(), 1e-8 * v.norm()) << stepped.transpose();
  EXPECT_GT((stepped - euler).norm(), 1e-3 * v.norm()) << "the implicit step is Euler's";
  const Vec position = Eigen::Map<const Vec>(raw.data->qpos, 2);
  EXPECT_LT((position - (q + h * stepped)).norm(), 1e-14);
  // MuJoCo's own Jacobian (mjData.qDeriv, dense here: nD = nv²) is the velocity derivative of
  // the Coriolis and centrifugal forces: nothing else depends on the velocity.
  ASSERT_EQ(raw.model->nD, 4);
  const RowMajor qDeriv = Eigen::Map<const RowMajor>(raw.data->qDeriv, 2, 2);
  EXPECT_LT((DenseMatrix(qDeriv) - D).norm(), 1e-6 * D.norm());
}

// The scheme on the problem's own Lagrangian in absolute angles θ (the joint angles are a constant
// linear map of θ, under which the scheme is invariant): M(θ)u̇ = F(θ, u) = L_q − (∂(M u)/∂θ)u,
// u⁺ = u + h(M − h ∂F/∂u)⁻¹F, θ⁺ = θ + hu⁺ (the relative energy error's maximum over the steps).
double velocity_implicit_euler_energy_error(const Problem& problem, double h, double t_end,
                                            bool coriolis_jacobian) {
  const LagrangianSystem& lagrangian = *problem.as_lagrangian();
  const auto force = [&](const Vec& theta, const Vec& u) {
    Vec L_q;
    lagrangian.lagrangian_q(theta, u, L_q);
    DenseMatrix D;
    lagrangian.mass_velocity_jacobian(theta, u, D);
    return Vec(L_q - D * u);
  };
  const State initial = problem.initial_state();
  Vec theta = initial.q, u = lagrangian.velocity(initial.q, initial.p);
  const double energy0 = problem.energy(initial.q, initial.p);
  double worst = 0;
  const int steps = static_cast<int>(std::lround(t_end / h));
  for (int k = 0; k < steps; ++k) {
    DenseMatrix M;
    lagrangian.mass_matrix(theta, M);
    const Vec F = force(theta, u);
    if (coriolis_jacobian) {
      M -= h * velocity_jacobian([&](const Vec& w) { return force(theta, w); }, u);
    }
    u += h * M.lu().solve(F);
    theta += h * u;
    const double energy = problem.energy(theta, lagrangian.momentum(theta, u));
    worst = std::max(worst, std::abs(energy - energy0) / std::abs(energy0));
  }
  return worst;
}

// The same maximum for a geomint method (here MuJoCo's, through its adapter).
double method_energy_error(const Problem& problem, const std::string& spec, double h,
                           double t_end) {
  const auto method = make_integrator(spec);
  State state = problem.initial_state();
  const double energy0 = problem.energy(state.q, state.p);
  method->reset(problem, state, h);
  double worst = 0;
  const int steps = static_cast<int>(std::lround(t_end / h));
  for (int k = 0; k < steps; ++k) {
    const StepStatus status = method->step(problem, state, h);
    EXPECT_TRUE(status.ok) << status.message;
    if (!status.ok) break;
    worst =
        std::max(worst, std::abs(problem.energy(state.q, state.p) - energy0) / std::abs(energy0));
  }
  return worst;
}

TEST(MujocoImplicit, TheSchemeOnTheProblemsOwnLagrangianGainsTheSameEnergy) {
  // The regular double pendulum of results/engines at h = 1/60 s over 20 s (before the growth
  // turns chaotic): MuJoCo's implicit step and the same scheme on the problem's Lagrangian gain
  // the same energy, five times what MuJoCo's Euler (and the scheme without the Jacobian) leave.
  const auto problem = make_problem("double_pendulum");
  const double h = 1.0 / 60, t_end = 20;
  const double implicit = method_energy_error(*problem, "mujoco:integrator=implicit", h, t_end);
  const double euler = method_energy_error(*problem, "mujoco:integrator=euler", h, t_end);
  const double scheme = velocity_implicit_euler_energy_error(*problem, h, t_end, true);
  const double scheme_euler = velocity_implicit_euler_energy_error(*problem, h, t_end, false);
  std::printf("energy error over 20 s: mujoco implicit %.6g, scheme %.6g; euler %.6g, %.6g\n",
              implicit, scheme, euler, scheme_euler);
  EXPECT_NEAR(scheme, implicit, 1e-6 * implicit);
  EXPECT_NEAR(scheme_euler, euler, 1e-9 * euler);
  EXPECT_GT(implicit, 5 * euler);
  // The gain is the scheme's error, not a fixed defect of the model: it falls with h (at 1/480 s
  // it is within 1.3 times Euler's).
  const double fine = velocity_implicit_euler_energy_error(*problem, h / 8, t_end, true);
  const double fine_euler = velocity_implicit_euler_energy_error(*problem, h / 8, t_end, false);
  EXPECT_LT(fine, 1.5 * fine_euler);
}

}  // namespace
}  // namespace geomint::engines
