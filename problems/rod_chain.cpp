// A planar chain of n rigid rods hanging from a fixed pivot under gravity (−y), in Cartesian node
// coordinates x_1 … x_n (2n dof) with one length constraint per rod (docs/METHOD.md §3;
// problems/rods.hpp): n = 1 is the Cartesian pendulum, n = 2 the (chaotic) double pendulum.
// `coordinates=joint`: the same chain in its absolute rod angles θ (n dof), mass
// M(θ)_ij = μ_ij l_i l_j cos(θ_i − θ_j), μ_ij = Σ_{k ≥ max(i,j)} m_k (../shared/MECHANICS.md §5).
#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "problems/articulated.hpp"
#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"
#include "problems/rods.hpp"

namespace geomint {
namespace {

// The Cartesian form's constrained steps solve dense systems in the 2n node coordinates and n
// multipliers: it keeps the cap it always had.
constexpr int kMaxCartesianRods = 64;

class RodChain final : public rods::RodProblem {
 public:
  RodChain(const Vec& node_mass, std::vector<rods::Rod> chain, double gravity, State initial)
      : RodProblem(std::move(chain), 2), gravity_(gravity), initial_(std::move(initial)) {
    Vec mass(2 * node_mass.size());
    for (int i = 0; i < node_mass.size(); ++i) mass.segment(2 * i, 2).setConstant(node_mass[i]);
    set_mass(mass);
    // The pivot is not a degree of freedom, so nothing is translation or rotation invariant:
    // no momentum capability; the motion is chaotic for n >= 2, so no exact solution either.
    set_capabilities(kHessian);
    double total_length = 0;
    for (const auto& rod : rods()) total_length += rod.length;
    const double time_unit = std::sqrt(total_length / gravity_);
    set_defaults(0.01 * time_unit, 100.0 * time_unit);
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override {
    double v = 0;
    for (int i = 1; i < q.size(); i += 2) v += mass()[i] * gravity_ * q[i];
    return v;
  }
  void gradient(const Vec& q, Vec& g) const override {
    g = Vec::Zero(q.size());
    for (int i = 1; i < q.size(); i += 2) g[i] = mass()[i] * gravity_;
  }
  // V is linear in the heights: ∇²V = 0 (declared for Newton-based constrained steps).
  void hessian(const Vec& q, SparseMatrix& H) const override {
    H.resize(q.size(), q.size());
    H.setZero();
    H.makeCompressed();
  }

  std::vector<std::string> multiplier_names() const override {
    std::vector<std::string> names;
    for (size_t i = 1; i <= rods().size(); ++i) names.push_back(fmt::format("tension{}", i));
    return names;
  }

 private:
  double gravity_;
  State initial_;
};

// The chain in joint (absolute) angles, θ_i from the downward vertical: a planar articulated
// chain (problems/articulated.hpp) whose links carry their mass at the tip (centre of mass at the
// rod's end, no inertia of their own). So T = ½ Σ_ij C_ij cos(θ_i − θ_j) θ̇_iθ̇_j with
// C_ij = μ_ij l_i l_j and V = −g Σ_i μ_ii l_i cos θ_i (μ_ii: the mass at and below node i), and
// the mass operator, ∂T/∂θ and the energy are the O(n) recursions; the dense members remain for
// the dense methods.
class RodChainJoint final : public Problem, public articulated::PlanarTreeLagrangian {
 public:
  const LagrangianSystem* as_lagrangian() const override { return this; }
  RodChainJoint(const Vec& node_mass, const Vec& length, double gravity, Vec theta, Vec omega)
      : PlanarTreeLagrangian(point_mass_chain(node_mass, length, gravity)),
        theta_(std::move(theta)),
        omega_(std::move(omega)) {
    set_dof(static_cast<int>(node_mass.size()));  // no constant mass: the mass is M(θ)
    set_capabilities(kOmegaMax);
    const double time_unit = std::sqrt(length.sum() / gravity);
    set_defaults(0.01 * time_unit, 100.0 * time_unit);
  }

  State initial_state() const override {
    return {0.0, theta_, static_cast<const LagrangianSystem&>(*this).momentum(theta_, omega_)};
  }

  // The fastest small-oscillation mode about the hanging chain, K v = ω²M(0)v (as
  // double_pendulum; dense, O(n³): only the stability search asks for it).
  double omega_max(const Vec&) const override {
    DenseMatrix M, K;
    const Vec hanging = Vec::Zero(dof());
    mass_matrix(hanging, M);
    potential_hessian(hanging, K);
    const Eigen::GeneralizedSelfAdjointEigenSolver<DenseMatrix> modes(K, M, Eigen::EigenvaluesOnly);
    return std::sqrt(modes.eigenvalues().maxCoeff());
  }
  double potential(const Vec& q) const override { return dynamics().potential(q); }
  void gradient(const Vec& q, Vec& g) const override { dynamics().potential_gradient(q, g); }

 private:
  static articulated::PlanarTree point_mass_chain(const Vec& node_mass, const Vec& length,
                                                  double gravity) {
    const int n = static_cast<int>(node_mass.size());
    std::vector<int> parent(n);
    for (int i = 0; i < n; ++i) parent[i] = i - 1;
    return {std::move(parent), node_mass, length, length, Vec::Zero(n), gravity};
  }
  Vec theta_, omega_;
};

}  // namespace

std::unique_ptr<Problem> make_rod_chain(Params& params) {
  const int n = static_cast<int>(
      params.integer("n", 2,
                     fmt::format("number of rods (and moving nodes); at most {} with "
                                 "coordinates=cartesian",
                                 kMaxCartesianRods),
                     1, articulated::kMaxLinks));
  const double mass = params.real("mass", 1.0, "mass of node 1", Range::above(0));
  const double mass_ratio =
      params.real("mass_ratio", 1.0, "mass of node i+1 / mass of node i", Range::above(0));
  const double length = params.real("length", 1.0, "length of rod 1", Range::above(0));
  const double length_ratio =
      params.real("length_ratio", 1.0, "length of rod i+1 / length of rod i", Range::above(0));
  const double gravity =
      params.real("gravity", 1.0, "gravitational acceleration (along -y)", Range::above(0));
  const double theta = params.real("theta", 2.0,
                                   "initial angle of every rod from the downward vertical (rad); "
                                   "theta<i> overrides it for rod i",
                                   Range::magnitude(1000));
  const double omega =
      params.real("omega", 0.0, "initial angular velocity of every rod (rad per time unit)");
  const std::string coordinates = params.choice(
      "coordinates", "cartesian", {"cartesian", "joint"},
      "Cartesian node coordinates with one length constraint per rod, or the n absolute rod "
      "angles with the mass M(theta) (non_separable)");
  // Every Cartesian spec (and committed result) stays as it was.
  params.omit_default_from_canonical("coordinates");
  if (coordinates == "cartesian" && n > kMaxCartesianRods) {
    throw InputError(fmt::format(
        "problem 'rod_chain': parameter n={} is too large for coordinates=cartesian; allowed: 1 "
        "to {} (coordinates=joint: 1 to {})",
        n, kMaxCartesianRods, articulated::kMaxLinks));
  }
  Vec node_mass(n), rod_lengths(n), angles(n);
  std::vector<rods::Rod> chain;
  State initial{0.0, Vec(2 * n), Vec(2 * n)};
  // Build the state from the angles, node by node from the pivot: every rod has its length and
  // every relative velocity is perpendicular to its rod, so the state is consistent by
  // construction (make_problem still checks it).
  double x = 0, y = 0, vx = 0, vy = 0;
  for (int i = 0; i < n; ++i) {
    const double angle =
        params.real(fmt::format("theta{}", i + 1), theta,
                    fmt::format("initial angle of rod {} (rad)", i + 1), Range::magnitude(1000));
    const double rod_length = length * std::pow(length_ratio, i);
    node_mass[i] = mass * std::pow(mass_ratio, i);
    if (!std::isfinite(rod_length) || !std::isfinite(node_mass[i]) || rod_length <= 0 ||
        node_mass[i] <= 0) {
      throw InputError(fmt::format(
          "problem 'rod_chain': mass_ratio or length_ratio give a non-positive or non-finite "
          "mass or length at node {} of {}",
          i + 1, n));
    }
    rod_lengths[i] = rod_length;
    angles[i] = angle;
    chain.push_back({i == 0 ? rods::kPivot : i - 1, i, rod_length});
    x += rod_length * std::sin(angle);
    y -= rod_length * std::cos(angle);
    vx += rod_length * omega * std::cos(angle);
    vy += rod_length * omega * std::sin(angle);
    initial.q.segment(2 * i, 2) << x, y;
    initial.p.segment(2 * i, 2) << node_mass[i] * vx, node_mass[i] * vy;
  }
  if (coordinates == "joint") {
    return std::make_unique<RodChainJoint>(node_mass, rod_lengths, gravity, angles,
                                           Vec::Constant(n, omega));
  }
  return std::make_unique<RodChain>(node_mass, std::move(chain), gravity, std::move(initial));
}

}  // namespace geomint
