// Rigid bodies about a fixed point from the problems' specs (engines/rotor.hpp).
#include "engines/rotor.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "engines/planar_chain.hpp"
#include "problems/lagrangian.hpp"
#include "problems/rigid_body.hpp"

namespace geomint::engines {
namespace {

double spec_real(const Spec& spec, const std::string& key) {
  const auto found = spec.values.find(key);
  if (found == spec.values.end()) {
    throw std::logic_error(
        fmt::format("engines: canonical spec of '{}' has no '{}'", spec.name, key));
  }
  return std::stod(found->second);
}

// The principal frame about the centre of mass, or "" → why no mass distribution has it.
std::string set_principal_frame(Rotor& rotor) {
  const Eigen::Vector3d& c = rotor.centre;
  const Eigen::Matrix3d about_centre =
      rotor.inertia -
      rotor.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  const bool diagonal =
      about_centre(0, 1) == 0 && about_centre(0, 2) == 0 && about_centre(1, 2) == 0;
  if (diagonal) {
    // Kept exact (no eigen-solver round-off) in the usual case of a centre on a principal axis.
    rotor.principal.setIdentity();
    rotor.principal_moments = about_centre.diagonal();
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(about_centre);
    rotor.principal = solver.eigenvectors();
    if (rotor.principal.determinant() < 0) rotor.principal.col(2) *= -1;
    rotor.principal_moments = solver.eigenvalues();
  }
  rotor.principal_centre = rotor.principal.transpose() * c;
  const Eigen::Vector3d& I = rotor.principal_moments;
  for (int k = 0; k < 3; ++k) {
    const double others = I[(k + 1) % 3] + I[(k + 2) % 3];
    if (!(I[k] > 0) || I[k] > others * (1 + 1e-12)) {
      return fmt::format(
          "its moments about the centre of mass, J - m(|chi|^2 1 - chi chi^T) = ({:.6g}, {:.6g}, "
          "{:.6g}) in principal axes, are not those of a mass distribution (each must be > 0 and "
          "at most the sum of the other two); a lighter body or a centre nearer the fixed point "
          "has one",
          I[0], I[1], I[2]);
    }
  }
  return "";
}

Eigen::Vector3d column(const Vec& x, int k) { return x.segment<3>(3 * k); }

}  // namespace

const std::vector<std::string>& rotor_problem_specs() {
  static const std::vector<std::string> specs = {
      "spherical_pendulum", "spherical_pendulum:coordinates=angles", "heavy_top", "rigid_body"};
  return specs;
}

std::optional<Rotor> rotor_of(const Problem& problem, std::string& why) {
  const Spec spec = Spec::parse(problem.spec());
  Rotor rotor;
  if (spec.name == "spherical_pendulum") {
    const bool angles =
        spec.values.count("coordinates") && spec.values.at("coordinates") == "angles";
    rotor.kind = angles ? Rotor::Kind::kSphericalAngles : Rotor::Kind::kSpherical;
    rotor.mass = spec_real(spec, "mass");
    rotor.length = spec_real(spec, "length");
    rotor.gravity = spec_real(spec, "gravity");
    rotor.centre = Eigen::Vector3d(0, 0, -rotor.length);
    // A point mass: T = ½m|Ω × χ|² = ½Ωᵀ m(|χ|²1 − χχᵀ)Ω, nothing about the rod's own axis.
    const double rod = rotor.mass * rotor.length * rotor.length;
    rotor.inertia = Eigen::Vector3d(rod, rod, 0).asDiagonal();
    rotor.principal_moments.setConstant(kPointMassInertia * rod);
    rotor.principal_centre = rotor.centre;
    return rotor;
  }
  if (spec.name == "heavy_top" || spec.name == "rigid_body") {
    const Eigen::Vector3d moments(spec_real(spec, "I1"), spec_real(spec, "I2"),
                                  spec_real(spec, "I3"));
    rotor.inertia = moments.asDiagonal();
    if (spec.name == "heavy_top") {
      rotor.kind = Rotor::Kind::kHeavyTop;
      rotor.mass = spec_real(spec, "m");
      rotor.gravity = spec_real(spec, "g");
      rotor.centre = Eigen::Vector3d(spec_real(spec, "chi1"), spec_real(spec, "chi2"),
                                     spec_real(spec, "chi3"));
    } else {
      // The free body turns about its centre of mass, which stays put: its mass moves nothing.
      rotor.kind = Rotor::Kind::kFreeBody;
      rotor.mass = 1;
    }
    if (std::string bad = set_principal_frame(rotor); !bad.empty()) {
      why = fmt::format("{} '{}': {}", spec.name, problem.spec(), bad);
      return std::nullopt;
    }
    return rotor;
  }
  why = fmt::format("problem '{}' is no rigid body about a fixed point", spec.name);
  return std::nullopt;
}

RotorState RotorStateMap::to_rotor(const Problem& problem, const State& state) {
  RotorState out;
  Eigen::Vector3d x = Eigen::Vector3d::Zero(), x_dot = Eigen::Vector3d::Zero();
  switch (rotor_.kind) {
    case Rotor::Kind::kHeavyTop:
    case Rotor::Kind::kFreeBody: {
      for (int k = 0; k < 3; ++k) out.attitude.col(k) = column(state.q, k);
      // Π = Qᵀ Σ c_k × p_k = JΩ on the manifold QᵀQ = 1.
      out.omega = rotor_.inertia.diagonal().cwiseInverse().cwiseProduct(
          rigid_body_body_momentum(state.q, state.p));
      return out;
    }
    case Rotor::Kind::kSpherical:
      x = state.q.head<3>();
      x_dot = state.p.head<3>().cwiseQuotient(problem.mass().head<3>());
      break;
    case Rotor::Kind::kSphericalAngles: {
      const Vec v = problem.as_lagrangian()->velocity(state.q, state.p);
      const double st = std::sin(state.q[0]), ct = std::cos(state.q[0]);
      const double sp = std::sin(state.q[1]), cp = std::cos(state.q[1]);
      const double L = rotor_.length;
      x << L * st * cp, L * st * sp, -L * ct;
      x_dot = L * v[0] * Eigen::Vector3d(ct * cp, ct * sp, st) +
              L * st * v[1] * Eigen::Vector3d(-sp, cp, 0);
      angles_ = state.q;
      break;
    }
  }
  // The bob on the rod's axis −e₃ of the body: the shortest rotation from −e₃ to x, and the spin
  // ω = x × ẋ/|x|² (none about the rod, which a point mass does not have).
  out.attitude =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d(0, 0, -1), x).toRotationMatrix();
  out.omega = out.attitude.transpose() * x.cross(x_dot) / x.squaredNorm();
  return out;
}

void RotorStateMap::to_problem(const Problem& problem, const RotorState& rotor_state,
                               State& state) {
  const Eigen::Matrix3d& Q = rotor_state.attitude;
  const Eigen::Vector3d& omega = rotor_state.omega;
  if (rotor_.kind == Rotor::Kind::kHeavyTop || rotor_.kind == Rotor::Kind::kFreeBody) {
    // q = vec(Q), p_k = d_k Q(Ω × e_k): the momentum of Q̇ = QΩ̂ (AttitudeProblem).
    state.q.resize(9);
    state.p.resize(9);
    for (int k = 0; k < 3; ++k) {
      state.q.segment<3>(3 * k) = Q.col(k);
      state.p.segment<3>(3 * k) =
          problem.mass()[3 * k] * (Q * omega.cross(Eigen::Vector3d::Unit(k)));
    }
    return;
  }
  const Eigen::Vector3d x = Q * rotor_.centre;
  const Eigen::Vector3d x_dot = Q * omega.cross(rotor_.centre);
  if (rotor_.kind == Rotor::Kind::kSpherical) {
    state.q = x;
    state.p = problem.mass().head<3>().cwiseProduct(x_dot);
    return;
  }
  // (θ, φ) on the branch of the last angles: θ ∈ [0, π] from the downward vertical, or its mirror
  // (−θ, φ + π) when the run's sin θ is negative, then the nearest whole turn of each.
  constexpr double kTurn = 2 * std::numbers::pi;
  double theta = std::atan2(std::hypot(x[0], x[1]), -x[2]);
  double phi = std::atan2(x[1], x[0]);
  if (angles_.size() == 2 && std::sin(angles_[0]) < 0) theta = -theta, phi += std::numbers::pi;
  if (angles_.size() == 2) {
    theta += kTurn * std::round((angles_[0] - theta) / kTurn);
    phi += kTurn * std::round((angles_[1] - phi) / kTurn);
  }
  const double st = std::sin(theta), ct = std::cos(theta);
  const double sp = std::sin(phi), cp = std::cos(phi);
  const double L = rotor_.length;
  Vec q(2), v(2);
  q << theta, phi;
  v << x_dot.dot(Eigen::Vector3d(ct * cp, ct * sp, st)) / L,
      x_dot.dot(Eigen::Vector3d(-sp, cp, 0)) / (L * st);
  state.q = q;
  state.p = problem.as_lagrangian()->momentum(q, v);
  angles_ = q;
}

RotorState RotorStateMap::to_principal(const RotorState& body) const {
  return {body.attitude * rotor_.principal, rotor_.principal.transpose() * body.omega};
}

RotorState RotorStateMap::from_principal(const RotorState& principal) const {
  return {principal.attitude * rotor_.principal.transpose(), rotor_.principal * principal.omega};
}

std::string engine_refusal(const Problem& problem, const std::string& method,
                           const std::string& engine) {
  std::string chain_why, rotor_why;
  if (planar_chain_of(problem, chain_why) || rotor_of(problem, rotor_why)) return "";
  std::vector<std::string> specs = chain_problem_specs();
  for (const auto& spec : rotor_problem_specs()) specs.push_back(spec);
  const bool is_rotor = Spec::parse(problem.spec()).name != "rod_chain" &&
                        rotor_why.find("no rigid body") == std::string::npos;
  return fmt::format(
      "method '{}' builds {} models of planar hinge chains and of one rigid body "
      "about a fixed point only: {}; problems that apply: {}",
      method, engine, is_rotor ? rotor_why : chain_why, fmt::join(specs, ", "));
}

}  // namespace geomint::engines
