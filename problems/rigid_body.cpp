// Free rigid body with the attitude Q ∈ SO(3) as 9 coordinates (its entries, column by column)
// and the 6 constraints QᵀQ = I (MECHANICS.md §6, GNI §VII.5): ½ΩᵀJΩ = ½tr(Q̇DQ̇ᵀ) with the
// constant masses d_k = ½(I1 + I2 + I3) − I_k, so RATTLE on it is the Moser–Veselov discrete body.
#include "problems/rigid_body.hpp"

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_mode.h>
#include <gsl/gsl_sf_ellint.h>
#include <gsl/gsl_sf_elljac.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace geomint {
namespace {

void check_gsl(int status, const char* function) {
  if (status != GSL_SUCCESS) {
    throw std::runtime_error(std::string("rigid body: ") + function +
                             " failed: " + gsl_strerror(status));
  }
}

// The 6 constraints in this order: the three column norms ½(|c_i|² − 1) (the ½ makes their
// Jacobian rows c_iᵀ, like those of the off-diagonal ones), then c_iᵀc_j for (i, j) = (0, 1),
// (0, 2), (1, 2).
constexpr std::array<std::array<int, 2>, 6> kPairs = {
    {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};

Eigen::Vector3d column(const Vec& x, int k) { return x.segment<3>(3 * k); }

// The free body: V = 0, and the Lie–Poisson structure (FreeRigidBodyStructure) through Q and Π.
class RigidBody final : public AttitudeProblem, public FreeRigidBodyStructure {
 public:
  const void* structure(const StructureKey& key) const override {
    if (const void* offered = offer<FreeRigidBodyStructure>(key, this)) return offered;
    return AttitudeProblem::structure(key);
  }
  RigidBody(const RigidBodyParameters& parameters, const Eigen::Matrix3d& attitude)
      : AttitudeProblem(parameters, attitude, kHessian | kAngularMomentum | kCasimir),
        flip_axis_(
            FreeBodyMotion(parameters.moments, parameters.moments.cwiseProduct(parameters.omega))
                .sign_changing_axis()) {}

  double potential(const Vec&) const override { return 0.0; }
  void gradient(const Vec&, Vec& g) const override { g = Vec::Zero(9); }
  // V = 0: ∇²V = 0, declared so that the Newton-based constrained steps can run.
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(9, 9);
    H.setZero();
    H.makeCompressed();
  }

  // |Π|² = |QJΩ|² on the manifold: kept by the motion and by any method that keeps the spatial
  // angular momentum and QᵀQ = I.
  double casimir(const Vec& q, const Vec& p) const override {
    return rigid_body_body_momentum(q, p).squaredNorm();
  }

  // The component of Π that changes sign once per period of the elliptic motion (Π₁ in the
  // tennis-racket flip about the intermediate axis 2), so period_measured times the flip on the
  // 9-coordinate body as on Euler's equations.
  double period_observable(const Vec& q, const Vec& p) const override {
    return rigid_body_body_momentum(q, p)[flip_axis_];
  }

  Eigen::Vector3d principal_moments() const override { return parameters().moments; }
  void read_body(const Vec& q, const Vec& p, Eigen::Matrix3d& attitude,
                 Eigen::Vector3d& body_momentum) const override {
    attitude = AttitudeProblem::attitude(q);
    body_momentum = rigid_body_body_momentum(q, p);
  }
  // q = vec(Q) and p_k = d_k Q(Ω × e_k) with Ω = J⁻¹Π: the momentum of the tangent velocity
  // Q̇ = QΩ̂, as initial_state() builds it.
  void write_body(const Eigen::Matrix3d& attitude, const Eigen::Vector3d& body_momentum, Vec& q,
                  Vec& p) const override {
    const Eigen::Vector3d omega = body_momentum.cwiseQuotient(parameters().moments);
    q.resize(9);
    p.resize(9);
    for (int k = 0; k < 3; ++k) {
      q.segment<3>(3 * k) = attitude.col(k);
      p.segment<3>(3 * k) = mass()[3 * k] * (attitude * omega.cross(Eigen::Vector3d::Unit(k)));
    }
  }

 private:
  int flip_axis_;
};

// Sign of the permutation (a, b, c) of (0, 1, 2).
double parity(const std::array<int, 3>& order) {
  int inversions = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) inversions += order[i] > order[j];
  return inversions % 2 == 0 ? 1.0 : -1.0;
}

}  // namespace

AttitudeProblem::AttitudeProblem(const RigidBodyParameters& parameters,
                                 const Eigen::Matrix3d& attitude, unsigned capabilities)
    : parameters_(parameters), attitude_(attitude) {
  const double half_trace = 0.5 * parameters.moments.sum();
  Vec mass(9);
  for (int k = 0; k < 3; ++k)
    mass.segment<3>(3 * k).setConstant(half_trace - parameters.moments[k]);
  set_mass(mass);
  set_capabilities(capabilities);
  // About 600 steps per radian of rotation at the initial rate, 100 radians.
  const double rate = parameters.omega.norm();
  const double unit = rate > 0 ? 1 / rate : 1.0;
  set_defaults(0.01 * unit, 100 * unit);
}

// Q̇ = QΩ̂, so column k moves at Q(Ω × e_k) and p_k = d_k Q(Ω × e_k).
State AttitudeProblem::initial_state() const {
  State state{0.0, Vec(9), Vec(9)};
  for (int k = 0; k < 3; ++k) {
    state.q.segment<3>(3 * k) = attitude_.col(k);
    const Eigen::Vector3d rate = attitude_ * parameters_.omega.cross(Eigen::Vector3d::Unit(k));
    state.p.segment<3>(3 * k) = mass()[3 * k] * rate;
  }
  return state;
}

Eigen::Matrix3d AttitudeProblem::attitude(const Vec& q) const {
  Eigen::Matrix3d Q;
  for (int k = 0; k < 3; ++k) Q.col(k) = column(q, k);
  return Q;
}

Vec AttitudeProblem::angular_momentum(const Vec& q, const Vec& p) const {
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) total += column(q, k).cross(column(p, k));
  return total;
}

void AttitudeProblem::constraint(const Vec& q, Vec& g) const {
  g.resize(6);
  for (int r = 0; r < 6; ++r) {
    const auto [i, j] = kPairs[r];
    const double dot = column(q, i).dot(column(q, j));
    g[r] = i == j ? 0.5 * (dot - 1) : dot;
  }
}

void AttitudeProblem::constraint_jacobian(const Vec& q, SparseMatrix& G) const {
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < 6; ++r) {
    const auto [i, j] = kPairs[r];
    for (int l = 0; l < 3; ++l) {
      entries.emplace_back(r, 3 * i + l, q[3 * j + l]);
      if (i != j) entries.emplace_back(r, 3 * j + l, q[3 * i + l]);
    }
  }
  G.resize(6, 9);
  G.setFromTriplets(entries.begin(), entries.end());
  G.makeCompressed();
}

// vᵀ∇²g_r v: |v_i|² for a norm, 2 v_i·v_j for an inner product.
void AttitudeProblem::constraint_curvature(const Vec&, const Vec& v, Vec& c) const {
  c.resize(6);
  for (int r = 0; r < 6; ++r) {
    const auto [i, j] = kPairs[r];
    c[r] = (i == j ? 1.0 : 2.0) * column(v, i).dot(column(v, j));
  }
}

// Σ λ_r ∇²g_r: λ_r I₃ on block (i, i) for a norm, on blocks (i, j) and (j, i) otherwise.
void AttitudeProblem::constraint_hessian(const Vec&, const Vec& lambda, SparseMatrix& K) const {
  std::vector<Eigen::Triplet<double>> entries;
  for (int r = 0; r < 6; ++r) {
    const auto [i, j] = kPairs[r];
    for (int l = 0; l < 3; ++l) {
      entries.emplace_back(3 * i + l, 3 * j + l, lambda[r]);
      if (i != j) entries.emplace_back(3 * j + l, 3 * i + l, lambda[r]);
    }
  }
  K.resize(9, 9);
  K.setFromTriplets(entries.begin(), entries.end());
  K.makeCompressed();
}

std::vector<std::string> AttitudeProblem::multiplier_names() const {
  return {"lambda11", "lambda22", "lambda33", "lambda12", "lambda13", "lambda23"};
}

std::vector<std::string> AttitudeProblem::series_names() const { return {"Pi1", "Pi2", "Pi3"}; }
void AttitudeProblem::series_values(const Vec& q, const Vec& p, std::vector<double>& values) const {
  const Eigen::Vector3d pi = rigid_body_body_momentum(q, p);
  values.assign(pi.data(), pi.data() + 3);
}

Eigen::Matrix3d read_initial_attitude(Params& params, const std::string& problem) {
  Eigen::Vector3d axis;
  axis[0] = params.real("axis1", 0.0, "initial attitude: rotation axis, component 1");
  axis[1] = params.real("axis2", 0.0, "initial attitude: rotation axis, component 2");
  axis[2] = params.real("axis3", 1.0, "initial attitude: rotation axis, component 3");
  const double angle = params.real(
      "angle", 0.0, "initial attitude: rotation angle about the axis (rad; 0: Q = I)",
      [](double x) { return std::abs(x) <= 1000; }, "|angle| <= 1000");
  if (!(axis.norm() > 0)) {
    throw InputError(fmt::format(
        "problem '{}': the attitude axis (axis1, axis2, axis3) must be nonzero", problem));
  }
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

RigidBodyParameters read_rigid_body_parameters(Params& params) {
  const auto positive = [](double x) { return x > 0; };
  RigidBodyParameters P;
  P.moments[0] =
      params.real("I1", 2.0, "principal moment of inertia about body axis 1", positive, "> 0");
  P.moments[1] =
      params.real("I2", 3.0, "principal moment of inertia about body axis 2", positive, "> 0");
  P.moments[2] =
      params.real("I3", 4.5, "principal moment of inertia about body axis 3", positive, "> 0");
  P.omega[0] = params.real("omega1", 0.8, "initial body angular velocity about axis 1");
  P.omega[1] = params.real("omega2", 0.3, "initial body angular velocity about axis 2");
  P.omega[2] = params.real("omega3", -0.6, "initial body angular velocity about axis 3");
  return P;
}

void check_attitude_masses(const RigidBodyParameters& parameters, const std::string& problem) {
  const Eigen::Vector3d& I = parameters.moments;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double others = I[i] + I[j];
    if (I[k] == others) {
      throw InputError(fmt::format(
          "problem '{}': I{} = {} equals I{} + I{} (a flat body, a lamina): its mass d{} = "
          "(I1+I2+I3)/2 - I{} is 0, so the mass tensor of the 9-coordinate form is singular (the "
          "kinetic energy needs its inverse); allowed: I{} < I{} + I{}. Euler's equations "
          "(rigid_body_euler) take any positive moments",
          problem, k + 1, I[k], i + 1, j + 1, k + 1, k + 1, k + 1, i + 1, j + 1));
    }
    if (!(I[k] < others)) {
      throw InputError(fmt::format(
          "problem '{}': I{} = {} must be < I{} + I{} = {} (triangle inequality of the principal "
          "moments: the mass d{} = (I1+I2+I3)/2 - I{} of the 9-coordinate form must be > 0, and no "
          "mass distribution has these moments). Euler's equations (rigid_body_euler) take any "
          "positive moments",
          problem, k + 1, I[k], i + 1, j + 1, others, k + 1, k + 1));
    }
  }
}

FreeBodyMotion::FreeBodyMotion(const Eigen::Vector3d& moments, const Eigen::Vector3d& pi0)
    : pi0_(pi0) {
  const Eigen::Vector3d& I = moments;
  if (pi0.squaredNorm() == 0) {
    steady_ = true;
    period_ = INFINITY;
    return;
  }
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int i, int j) { return I[i] < I[j]; });
  const int a = order[0], b = order[1], c = order[2];
  if (I[a] == I[b] || I[b] == I[c]) {
    why_not_ = "equal principal moments (a symmetric body): no elliptic solution offered";
    return;
  }
  // |Π|² − 2E I_x = Σ_k Π_k²(I_k − I_x)/I_k: written as a sum of terms of one sign about an
  // extreme axis, so only the separatrix test itself cancels.
  const auto offset = [&](int axis) {
    double sum = 0;
    for (int k = 0; k < 3; ++k) sum += pi0[k] * pi0[k] * (I[k] - I[axis]) / I[k];
    return sum;
  };
  const double separatrix = offset(b);
  if (std::abs(separatrix) <= 1e-12 * pi0.squaredNorm()) {
    why_not_ = "on the separatrix |Pi|^2 = 2 E I (intermediate): no periodic solution";
    return;
  }
  z_ = separatrix > 0 ? c : a;
  x_ = separatrix > 0 ? a : c;
  y_ = b;
  const double pz = std::abs(offset(z_));  // |2E I_z − |Π|²|
  const double px = std::abs(offset(x_));  // ||Π|² − 2E I_x|
  if (pz == 0) {                           // a rotation about the axis z: Π stays put
    steady_ = true;
    period_ = INFINITY;
    return;
  }
  const double Ix = I[x_], Iy = I[y_], Iz = I[z_];
  amplitude_x_ = std::sqrt(Ix * pz / std::abs(Iz - Ix));
  amplitude_y_ = std::sqrt(Iy * pz / std::abs(Iz - Iy));
  amplitude_z_ = std::sqrt(Iz * px / std::abs(Iz - Ix));
  const double m = std::abs(Iy - Ix) * pz / (std::abs(Iz - Iy) * px);
  k_ = std::sqrt(m);
  lambda_ = std::sqrt(px * std::abs(Iz - Iy) / (Ix * Iy * Iz));
  epsilon_ = pi0[z_] >= 0 ? 1.0 : -1.0;
  rho_ = parity(order);
  quarter_ = gsl_sf_ellint_Kcomp(k_, GSL_PREC_DOUBLE);
  // sn u₀ = εΠ_y(0)/B, cn u₀ = Π_x(0)/A: u₀ = F(φ₀ | k) with the amplitude φ₀ in (−π, π],
  // F(π − φ) = 2K − F(φ) for the outer quarters (F itself is only used on |φ| ≤ π/2).
  const double phi0 = std::atan2(epsilon_ * pi0[y_] / amplitude_y_, pi0[x_] / amplitude_x_);
  const bool outer = std::abs(phi0) > M_PI / 2;
  const double inner = outer ? std::copysign(M_PI, phi0) - phi0 : phi0;
  gsl_sf_result f;
  check_gsl(gsl_sf_ellint_F_e(inner, k_, GSL_PREC_DOUBLE, &f), "gsl_sf_ellint_F_e");
  u0_ = outer ? std::copysign(2 * quarter_, phi0) - f.val : f.val;
  period_ = 4 * quarter_ / lambda_;
}

Eigen::Vector3d FreeBodyMotion::at(double t) const {
  if (!why_not_.empty()) throw std::logic_error("FreeBodyMotion::at: " + why_not_);
  if (steady_) return pi0_;
  // Reduce the argument modulo the period 4K of sn and cn so late times keep their digits.
  double u = std::fmod(rho_ * lambda_ * t + u0_, 4 * quarter_);
  double sn, cn, dn;
  check_gsl(gsl_sf_elljac_e(u, k_ * k_, &sn, &cn, &dn), "gsl_sf_elljac_e");
  Eigen::Vector3d pi;
  pi[x_] = amplitude_x_ * cn;
  pi[y_] = epsilon_ * amplitude_y_ * sn;
  pi[z_] = epsilon_ * amplitude_z_ * dn;
  return pi;
}

Eigen::Vector3d rigid_body_body_momentum(const Vec& q, const Vec& p) {
  Eigen::Vector3d spatial = Eigen::Vector3d::Zero();
  Eigen::Matrix3d Q;
  for (int k = 0; k < 3; ++k) {
    Q.col(k) = column(q, k);
    spatial += column(q, k).cross(column(p, k));
  }
  return Q.transpose() * spatial;
}

std::unique_ptr<Problem> make_rigid_body(Params& params) {
  const RigidBodyParameters P = read_rigid_body_parameters(params);
  check_attitude_masses(P, "rigid_body");
  return std::make_unique<RigidBody>(P, read_initial_attitude(params, "rigid_body"));
}

}  // namespace geomint
