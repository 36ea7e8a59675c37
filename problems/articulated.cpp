// Planar articulated bodies in absolute link angles (problems/articulated.hpp): the O(n) recursions
// and the problems articulated_chain, rope and branching (uniform rods on revolute joints with
// parallel axes; spherical joints are not offered yet).
#include "problems/articulated.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>
#include <string>

#include "problems/spec.hpp"

namespace geomint {
namespace articulated {
namespace {

thread_local long passes_on_this_thread = 0;

// Every 2-vector is stored in its link's frame: components along e′_a = (cos θ_a, sin θ_a) (across
// the link) and e_a = (sin θ_a, −cos θ_a) (along it). Frames differ by the joint's relative angle
// δ = θ_a − θ_parent, so a straight chain (δ = 0) rotates exactly and its ∂T/∂θ is exactly 0.
// To the child's frame: x_a = R(δ) x_parent; back: x_parent = R(δ)ᵀ x_a.
Eigen::Matrix2d to_child(double delta) {
  const double c = std::cos(delta), s = std::sin(delta);
  Eigen::Matrix2d R;
  R << c, -s, s, c;
  return R;
}
const Eigen::Vector2d kAcross(1, 0);  // e′_a in its own frame

}  // namespace

long thread_passes() { return passes_on_this_thread; }

void PlanarTreeDynamics::count(long passes) const {
  passes_.fetch_add(passes, std::memory_order_relaxed);
  passes_on_this_thread += passes;
}

PlanarTreeDynamics::PlanarTreeDynamics(PlanarTree tree) : tree_(std::move(tree)) {
  const int n = size();
  if (n < 1 || tree_.mass.size() != n || tree_.length.size() != n || tree_.com.size() != n ||
      tree_.inertia.size() != n) {
    throw std::invalid_argument("PlanarTree: every per-link vector needs one entry per link");
  }
  for (int a = 0; a < n; ++a) {
    if (tree_.parent[a] < PlanarTree::kPivot || tree_.parent[a] >= a) {
      throw std::invalid_argument("PlanarTree: parent[a] must be the pivot or a link before a");
    }
    // I_a + m_a c_a² > 0 keeps every articulated inertia D_a of solve_mass positive.
    if (!(tree_.mass[a] > 0) || !(tree_.length[a] > 0) || !(tree_.inertia[a] >= 0) ||
        !(tree_.inertia[a] + tree_.mass[a] * tree_.com[a] * tree_.com[a] > 0)) {
      throw std::invalid_argument("PlanarTree: a link has a non-positive mass, length or inertia");
    }
  }
  Vec descendant_mass = Vec::Zero(n);  // W_a
  for (int a = n - 1; a >= 0; --a) {
    if (tree_.parent[a] != PlanarTree::kPivot) {
      descendant_mass[tree_.parent[a]] += tree_.mass[a] + descendant_mass[a];
    }
  }
  moment_.resize(n);
  self_.resize(n);
  for (int a = 0; a < n; ++a) {
    const double m = tree_.mass[a], c = tree_.com[a], l = tree_.length[a];
    moment_[a] = m * c + l * descendant_mass[a];
    self_[a] = tree_.inertia[a] + m * c * c + l * l * descendant_mass[a];
  }
  weight_ = tree_.gravity * moment_;
}

void PlanarTreeDynamics::link_momenta(const Vec& theta, const Vec& u,
                                      Eigen::Matrix2Xd& lever) const {
  const int n = size();
  // Pass 1, from the pivot: centre-of-mass velocities V_a (link frames).
  std::vector<Eigen::Matrix2d> rotation(n);
  Eigen::Matrix2Xd joint(2, n), com_velocity(2, n);
  for (int a = 0; a < n; ++a) {
    const int up = tree_.parent[a];
    if (up == PlanarTree::kPivot) {
      joint.col(a).setZero();
    } else {
      rotation[a] = to_child(theta[a] - theta[up]);
      joint.col(a) = rotation[a] * (joint.col(up) + tree_.length[up] * u[up] * kAcross);
    }
    com_velocity.col(a) = joint.col(a) + tree_.com[a] * u[a] * kAcross;
  }
  // Pass 2, from the leaves: S_a (descendants' momentum) and lever_a = m_a c_a V_a + l_a S_a.
  Eigen::Matrix2Xd descendants = Eigen::Matrix2Xd::Zero(2, n);
  lever.resize(2, n);
  for (int a = n - 1; a >= 0; --a) {
    lever.col(a) =
        tree_.mass[a] * tree_.com[a] * com_velocity.col(a) + tree_.length[a] * descendants.col(a);
    if (tree_.parent[a] != PlanarTree::kPivot) {
      descendants.col(tree_.parent[a]) +=
          rotation[a].transpose() * (tree_.mass[a] * com_velocity.col(a) + descendants.col(a));
    }
  }
  count(2);
}

// e′_a·lever_a and e_a·lever_a are lever's own-frame components.
void PlanarTreeDynamics::apply_mass(const Vec& theta, const Vec& u, Vec& Mu) const {
  Eigen::Matrix2Xd lever;
  link_momenta(theta, u, lever);
  Mu = tree_.inertia.cwiseProduct(u) + lever.row(0).transpose();
}

void PlanarTreeDynamics::kinetic_gradient(const Vec& theta, const Vec& u, Vec& T_q) const {
  Eigen::Matrix2Xd lever;
  link_momenta(theta, u, lever);
  T_q = -u.cwiseProduct(lever.row(1).transpose());
}

double PlanarTreeDynamics::kinetic_energy(const Vec& theta, const Vec& u) const {
  Vec Mu;
  apply_mass(theta, u, Mu);
  return 0.5 * u.dot(Mu);
}

// With the children's P_c = K_c U_c + k_c and U_c = U_a + l_a u_a e′_a, p_a = (Mu)_a reads
// p_a = D_a u_a + h_a·U_a + l_a e′_a·k̄_a (K̄, k̄: the sums over a's children), so
// u_a = (r_a − h_a·U_a)/D_a with r_a = p_a − l_a e′_a·k̄_a, and a's own subtree has
// K_a = m_a 1 + K̄_a − h_a h_aᵀ/D_a, k_a = k̄_a + h_a r_a/D_a (all in link a's frame).
void PlanarTreeDynamics::solve_mass(const Vec& theta, const Vec& p, Vec& u,
                                    const Vec* inertia_shift) const {
  const int n = size();
  std::vector<Eigen::Matrix2d> inertia_sum(n, Eigen::Matrix2d::Zero());  // K̄_a
  std::vector<Eigen::Matrix2d> rotation(n);
  Eigen::Matrix2Xd bias_sum = Eigen::Matrix2Xd::Zero(2, n);  // k̄_a
  Eigen::Matrix2Xd coupling(2, n);                           // h_a
  Vec pivot_inertia(n), rest(n);                             // D_a, r_a
  for (int a = n - 1; a >= 0; --a) {
    const double m = tree_.mass[a], c = tree_.com[a], l = tree_.length[a];
    const Eigen::Vector2d K_across = inertia_sum[a].col(0);
    coupling.col(a) = m * c * kAcross + l * K_across;
    pivot_inertia[a] = tree_.inertia[a] + m * c * c + l * l * K_across[0];
    if (inertia_shift != nullptr) pivot_inertia[a] += (*inertia_shift)[a];
    rest[a] = p[a] - l * bias_sum(0, a);
    const int up = tree_.parent[a];
    if (up == PlanarTree::kPivot) continue;  // the pivot does not move: K_a is not needed
    rotation[a] = to_child(theta[a] - theta[up]);
    const Eigen::Vector2d h = coupling.col(a);
    const Eigen::Matrix2d subtree =
        m * Eigen::Matrix2d::Identity() + inertia_sum[a] - h * h.transpose() / pivot_inertia[a];
    inertia_sum[up] += rotation[a].transpose() * subtree * rotation[a];
    bias_sum.col(up) +=
        rotation[a].transpose() * (bias_sum.col(a) + h * (rest[a] / pivot_inertia[a]));
  }
  Eigen::Matrix2Xd joint(2, n);
  u.resize(n);
  for (int a = 0; a < n; ++a) {
    const int up = tree_.parent[a];
    if (up == PlanarTree::kPivot) {
      joint.col(a).setZero();
    } else {
      joint.col(a) = rotation[a] * (joint.col(up) + tree_.length[up] * u[up] * kAcross);
    }
    u[a] = (rest[a] - coupling.col(a).dot(joint.col(a))) / pivot_inertia[a];
  }
  count(2);
}

double PlanarTreeDynamics::potential(const Vec& theta) const {
  return -weight_.dot(theta.array().cos().matrix());
}

void PlanarTreeDynamics::potential_gradient(const Vec& theta, Vec& g) const {
  g = weight_.cwiseProduct(theta.array().sin().matrix());
}

void PlanarTreeDynamics::potential_hessian(const Vec& theta, DenseMatrix& K) const {
  K = weight_.cwiseProduct(theta.array().cos().matrix()).asDiagonal();
}

template <typename Visit>
void PlanarTreeDynamics::for_each_related_pair(Visit visit) const {
  for (int b = 0; b < size(); ++b) {
    for (int a = tree_.parent[b]; a != PlanarTree::kPivot; a = tree_.parent[a]) {
      visit(a, b, tree_.length[a] * moment_[b]);
    }
  }
}

void PlanarTreeDynamics::mass_matrix(const Vec& theta, DenseMatrix& M) const {
  M = DenseMatrix::Zero(size(), size());
  M.diagonal() = self_;
  for_each_related_pair(
      [&](int a, int b, double C) { M(a, b) = M(b, a) = C * std::cos(theta[a] - theta[b]); });
}

// (Mu)_a = Σ_b C_ab cos(θ_a − θ_b) u_b: ∂/∂θ_b = C_ab sin(θ_a − θ_b) u_b for b ≠ a, and minus
// the row's sum of those on the diagonal.
void PlanarTreeDynamics::mass_velocity_jacobian(const Vec& theta, const Vec& u,
                                                DenseMatrix& D) const {
  D = DenseMatrix::Zero(size(), size());
  for_each_related_pair([&](int a, int b, double C) {
    const double s = std::sin(theta[a] - theta[b]);
    D(a, b) = C * s * u[b];
    D(a, a) -= C * s * u[b];
    D(b, a) = -C * s * u[a];
    D(b, b) += C * s * u[a];
  });
}

// ∂²T/∂θ_a∂θ_b = C_ab cos(θ_a − θ_b) u_a u_b for b ≠ a; the diagonal is minus the row's rest.
void PlanarTreeDynamics::kinetic_hessian(const Vec& theta, const Vec& u, DenseMatrix& T_qq) const {
  T_qq = DenseMatrix::Zero(size(), size());
  for_each_related_pair([&](int a, int b, double C) {
    const double term = C * std::cos(theta[a] - theta[b]) * u[a] * u[b];
    T_qq(a, b) = T_qq(b, a) = term;
    T_qq(a, a) -= term;
    T_qq(b, b) -= term;
  });
}

}  // namespace articulated

namespace {

using articulated::PlanarTree;

// A tree of uniform rods (centre of mass at mid-length) in absolute angles, as a Problem.
class ArticulatedProblem final : public Problem, public articulated::PlanarTreeLagrangian {
 public:
  ArticulatedProblem(PlanarTree tree, const Vec& theta, const Vec& omega)
      : PlanarTreeLagrangian(std::move(tree)), theta_(theta) {
    const auto& links = dynamics().tree();
    const int n = dynamics().size();
    set_dof(n);  // no constant mass: the mass is M(θ)
    dynamics().apply_mass(theta_, omega, momentum_);
    // Rotating the whole tree about the pivot is a symmetry only without gravity.
    set_capabilities(links.gravity == 0 ? kAngularMomentum : 0u);
    // The default step resolves the fastest small oscillation about the hanging tree (dense,
    // up to 64 links; beyond, a hanging chain's, which grows like n√(g/L)) and the initial
    // spin, and is never coarser than rod_chain's 0.01 time units.
    const double time_unit =
        links.gravity > 0 ? std::sqrt(links.length.sum() / links.gravity) : 1.0;
    double dt = std::min(0.01, 0.25 / n) * time_unit;
    if (n <= 64 && links.gravity > 0) {
      DenseMatrix M, K;
      const Vec hanging = Vec::Zero(n);
      dynamics().mass_matrix(hanging, M);
      dynamics().potential_hessian(hanging, K);
      const Eigen::GeneralizedSelfAdjointEigenSolver<DenseMatrix> modes(K, M,
                                                                        Eigen::EigenvaluesOnly);
      dt = std::min(0.01 * time_unit, 0.02 / std::sqrt(modes.eigenvalues().maxCoeff()));
    }
    const double spin = omega.cwiseAbs().maxCoeff();
    if (spin > 0) dt = std::min(dt, 0.02 / spin);
    set_defaults(dt, 20.0 * time_unit);
  }
  const LagrangianSystem* as_lagrangian() const override { return this; }

  State initial_state() const override { return {0.0, theta_, momentum_}; }
  double potential(const Vec& q) const override { return dynamics().potential(q); }
  void gradient(const Vec& q, Vec& g) const override { dynamics().potential_gradient(q, g); }
  Vec angular_momentum(const Vec&, const Vec& p) const override {
    return Vec::Constant(1, articulated::PlanarTreeDynamics::angular_momentum(p));
  }

 private:
  Vec theta_, momentum_;
};

// n from 1 to the stated limit; the message names the parameter and the range.
int read_link_count(Params& params, const std::string& key, long default_value,
                    const std::string& help) {
  return static_cast<int>(params.integer(key, default_value, help, 1, articulated::kMaxLinks));
}

// A per-link quantity: the list `plural` (a/b/c, exactly n entries) when given, otherwise the
// scalar for every link. `positive` requires every entry > 0.
Vec per_link(Params& params, const std::string& plural, double scalar, int n, bool positive,
             const std::string& help) {
  const std::vector<double> values = params.reals(plural, help);
  if (values.empty()) return Vec::Constant(n, scalar);
  if (static_cast<int>(values.size()) != n) {
    throw InputError(fmt::format(
        "problem '{}': parameter {} has {} entries; allowed: exactly n = {} entries a/b/c, one "
        "per link",
        params.name(), plural, values.size(), n));
  }
  Vec out(n);
  for (int i = 0; i < n; ++i) {
    if (positive && !(values[i] > 0)) {
      throw InputError(fmt::format("problem '{}': parameter {} entry {} is {}; allowed: > 0",
                                   params.name(), plural, i + 1, values[i]));
    }
    if (!positive && !(std::abs(values[i]) <= 1000)) {
      throw InputError(
          fmt::format("problem '{}': parameter {} entry {} is {}; allowed: |x| <= 1000",
                      params.name(), plural, i + 1, values[i]));
    }
    out[i] = values[i];
  }
  return out;
}

// The links' parameters shared by articulated_chain and branching, for a tree of n links.
std::unique_ptr<Problem> make_tree(Params& params, std::vector<int> parent) {
  const int n = static_cast<int>(parent.size());
  const double mass =
      params.real("mass", 1.0, "mass of every link (masses=a/b/c per link)", Range::above(0));
  const Vec masses = per_link(params, "masses", mass, n, true, "mass of each link, n entries");
  const double length =
      params.real("length", 1.0, "length of every link (lengths=a/b/c per link)", Range::above(0));
  const Vec lengths =
      per_link(params, "lengths", length, n, true, "length of each link, n entries");
  // Not given, each link's inertia is its own m l²/12, which no single default value states: the
  // key then stays out of the canonical spec, so that the spec rebuilds the same tree.
  const bool inertia_given = params.given("inertia");
  const double inertia = params.real(
      "inertia", mass * length * length / 12,
      "moment of inertia of every link about its centre (default m l^2/12, a uniform rod; "
      "inertias=a/b/c per link)",
      Range::above(0));
  if (!inertia_given) params.omit_default_from_canonical("inertia");
  Vec inertias = per_link(params, "inertias", inertia, n, true,
                          "moment of inertia of each link about its centre, n entries");
  if (!inertia_given && !params.given("inertias")) {
    inertias = masses.cwiseProduct(lengths.cwiseAbs2()) / 12;  // uniform rods, link by link
  }
  const double gravity = params.real(
      "gravity", 1.0,
      "gravitational acceleration along -y (0: the angular momentum about the pivot is conserved)",
      Range::at_least(0));
  const double theta = params.real("theta", 0.5,
                                   "initial absolute angle of every link from the downward "
                                   "vertical (rad; thetas=a/b/c per link)",
                                   Range::magnitude(1000));
  const Vec thetas =
      per_link(params, "thetas", theta, n, false, "initial angle of each link (rad)");
  const double omega = params.real("omega", 0.0,
                                   "initial angular velocity of every link (rad per time unit; "
                                   "omegas=a/b/c per link)",
                                   Range::magnitude(1000));
  const Vec omegas =
      per_link(params, "omegas", omega, n, false, "initial angular velocity of each link");
  PlanarTree tree{std::move(parent), masses, lengths, lengths / 2, inertias, gravity};
  return std::make_unique<ArticulatedProblem>(std::move(tree), thetas, omegas);
}

}  // namespace

std::unique_ptr<Problem> make_articulated_chain(Params& params) {
  const int n = read_link_count(params, "n", 4, "number of links (a chain from the pivot)");
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i - 1;  // link 0 hangs from the pivot
  return make_tree(params, std::move(parent));
}

std::unique_ptr<Problem> make_branching(Params& params) {
  const std::vector<double> parents = params.reals(
      "parents",
      "parent of each link, 1-based, 0 = the pivot; link i's parent must come before it "
      "(default 0/1/1/2/2/3/3, a binary tree of 7 links)");
  std::vector<int> parent;
  if (parents.empty()) {
    parent = {-1, 0, 0, 1, 1, 2, 2};
  } else {
    if (static_cast<int>(parents.size()) > articulated::kMaxLinks) {
      throw InputError(fmt::format(
          "problem 'branching': parameter parents has {} entries; allowed: 1 to {} links",
          parents.size(), articulated::kMaxLinks));
    }
    for (size_t i = 0; i < parents.size(); ++i) {
      const double value = parents[i];
      if (value != std::floor(value) || value < 0 || value > static_cast<double>(i)) {
        throw InputError(fmt::format(
            "problem 'branching': parameter parents entry {} is {}; allowed: an integer from 0 "
            "(the pivot) to {} (a link before it)",
            i + 1, value, i));
      }
      parent.push_back(static_cast<int>(value) - 1);
    }
  }
  return make_tree(params, std::move(parent));
}

std::unique_ptr<Problem> make_rope(Params& params) {
  const int n = read_link_count(params, "n", 8, "number of links (a long rope: n=256 … 4096)");
  const double total_mass = params.real("mass", 1.0, "total mass", Range::above(0));
  const double total_length = params.real("length", 1.0, "total length", Range::above(0));
  const double gravity =
      params.real("gravity", 1.0, "gravitational acceleration along -y", Range::above(0));
  const double amplitude =
      params.real("amplitude", 0.3,
                  "initial angle of the straight rope from the downward vertical (rad); it starts "
                  "at rest",
                  Range::magnitude(3.2));
  const double link_mass = total_mass / n, link_length = total_length / n;
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i - 1;
  PlanarTree tree{std::move(parent),
                  Vec::Constant(n, link_mass),
                  Vec::Constant(n, link_length),
                  Vec::Constant(n, link_length / 2),
                  Vec::Constant(n, link_mass * link_length * link_length / 12),
                  gravity};
  return std::make_unique<ArticulatedProblem>(std::move(tree), Vec::Constant(n, amplitude),
                                              Vec::Zero(n));
}

}  // namespace geomint
