// Free-floating 2D/3D spring lattice: springs φ(r) = ½k(r − L)² + ¼k₄(r − L)⁴, r = |q_j − q_i|,
// optional damping along the springs. All forces depend on q_j − q_i only, so linear and angular
// momentum are conserved (the discrete Noether check, docs/METHOD.md claim 1 and §6).
#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "problems/force.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

struct SpringNetConfig {
  int nx = 8, ny = 8, nz = 1;
  double spacing = 1;
  double mass = 1;
  double stiffness = 100;
  double quartic = 0;  // k₄; zero for the Hookean model
  bool diagonals = true;
  double rest_perturbation = 0.1;
  double position_jitter = 0.05;
  double velocity = 1;
  double spin = 0.5;
  double drift = 0.3;
  unsigned long seed = 1;
  double damping = 0;
};

struct Spring {
  int i;  // node indices, i < j
  int j;
  double rest;  // L
};

template <int Dim>
class SpringNet final : public Problem, public NonConservativeForce {
  using Point = Eigen::Matrix<double, Dim, 1>;
  using Block = Eigen::Matrix<double, Dim, Dim>;
  using Triplets = std::vector<Eigen::Triplet<double>>;

 public:
  explicit SpringNet(const SpringNetConfig& config)
      : nodes_(config.nx * config.ny * config.nz),
        stiffness_(config.stiffness),
        quartic_(config.quartic),
        damping_(config.damping) {
    set_mass(Vec::Constant(Dim * nodes_, config.mass));
    set_capabilities(kHessian | kLinearMomentum | kAngularMomentum | kOmegaMax);
    set_defaults(0.01, 10.0);
    build(config);
  }

  State initial_state() const override { return initial_; }

  double potential(const Vec& q) const override {
    double sum = 0;
    for (const Spring& spring : springs_) {
      const double stretch = (point(q, spring.j) - point(q, spring.i)).norm() - spring.rest;
      const double stretch2 = stretch * stretch;
      sum += stretch2 * (0.5 * stiffness_ + 0.25 * quartic_ * stretch2);
    }
    return sum;
  }

  void gradient(const Vec& q, Vec& g) const override {
    g.setZero(dof());
    for (const Spring& spring : springs_) {
      const Point d = point(q, spring.j) - point(q, spring.i);
      const double r = d.norm();
      const Point pull = (tension(r - spring.rest) / r) * d;
      g.template segment<Dim>(Dim * spring.j) += pull;
      g.template segment<Dim>(Dim * spring.i) -= pull;
    }
  }

  void hessian(const Vec& q, SparseMatrix& H) const override {
    Triplets triplets;
    triplets.reserve(4 * Dim * Dim * springs_.size());
    for (const Spring& spring : springs_) {
      add_spring_blocks(spring, hessian_block(spring, point(q, spring.j) - point(q, spring.i)),
                        triplets);
    }
    H.resize(dof(), dof());
    H.setFromTriplets(triplets.begin(), triplets.end());
  }

  // The damping force c ṙ n acts along the spring in equal and opposite pairs, so it has zero net
  // force and torque; its power −c ṙ² ≤ 0 with ṙ = n·(v_j − v_i) the extension rate.
  const NonConservativeForce* as_forced() const override { return damping_ > 0 ? this : nullptr; }
  bool has_force_jacobian() const override { return true; }
  void force(const Vec& q, const Vec& v, double, Vec& f) const override {
    f.setZero(dof());
    for (const Spring& spring : springs_) {
      const Point n = (point(q, spring.j) - point(q, spring.i)).normalized();
      const double extension_rate = n.dot(point(v, spring.j) - point(v, spring.i));
      const Point resistance = (damping_ * extension_rate) * n;
      f.template segment<Dim>(Dim * spring.i) += resistance;
      f.template segment<Dim>(Dim * spring.j) -= resistance;
    }
  }

  // C = −∂F/∂v = Σ c n nᵀ in the pattern [+ −; − +]: symmetric PSD. The dependence of F on q
  // through n is left out (it is not a damping matrix); callers that need it difference it.
  void force_jacobian_v(const Vec& q, const Vec&, double, SparseMatrix& C) const override {
    Triplets triplets;
    triplets.reserve(4 * Dim * Dim * springs_.size());
    for (const Spring& spring : springs_) {
      const Point n = (point(q, spring.j) - point(q, spring.i)).normalized();
      add_spring_blocks(spring, damping_ * outer(n), triplets);
    }
    C.resize(dof(), dof());
    C.setFromTriplets(triplets.begin(), triplets.end());
  }

  Vec linear_momentum(const Vec&, const Vec& p) const override {
    Point total = Point::Zero();
    for (int node = 0; node < nodes_; ++node) total += point(p, node);
    return total;
  }

  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    if constexpr (Dim == 2) {
      double total = 0;
      for (int node = 0; node < nodes_; ++node) {
        total += q[2 * node] * p[2 * node + 1] - q[2 * node + 1] * p[2 * node];
      }
      return Vec::Constant(1, total);
    } else {
      Point total = Point::Zero();
      for (int node = 0; node < nodes_; ++node) total += point(q, node).cross(point(p, node));
      return total;
    }
  }

  // Gershgorin: every eigenvalue of M⁻¹∇²V lies in a disc centred on a diagonal entry with the
  // row's off-diagonal absolute sum as radius, so λ_max ≤ max_i Σ_j |∇²V_ij| / m_i. M⁻¹∇²V is
  // similar to the symmetric M^(−½)∇²V M^(−½), whose eigenvalues are the squared linearised
  // frequencies. The row sums are those of the assembled Hessian, built without assembling it.
  double omega_max(const Vec& q) const override {
    std::vector<Block> diagonal(nodes_, Block::Zero());
    Vec off_diagonal_sums = Vec::Zero(dof());
    for (const Spring& spring : springs_) {
      const Block block = hessian_block(spring, point(q, spring.j) - point(q, spring.i));
      diagonal[spring.i] += block;
      diagonal[spring.j] += block;
      const Point row_sums = block.cwiseAbs().rowwise().sum();
      off_diagonal_sums.template segment<Dim>(Dim * spring.i) += row_sums;
      off_diagonal_sums.template segment<Dim>(Dim * spring.j) += row_sums;
    }
    double bound = 0;
    for (int node = 0; node < nodes_; ++node) {
      const Point row_sums = diagonal[node].cwiseAbs().rowwise().sum() +
                             off_diagonal_sums.template segment<Dim>(Dim * node);
      bound = std::max(
          bound,
          row_sums.cwiseProduct(inverse_mass().template segment<Dim>(Dim * node)).maxCoeff());
    }
    return std::sqrt(bound);
  }

 private:
  static Point point(const Vec& x, int node) { return x.template segment<Dim>(Dim * node); }

  // n nᵀ evaluated before any scaling, so that blocks, and the assembled matrices, are symmetric
  // to the last bit (s·n_r·n_c and s·n_c·n_r can round differently).
  static Block outer(const Point& n) {
    Block product = n * n.transpose();
    return product;
  }

  // φ'(r) and φ''(r) as functions of the stretch r − L.
  double tension(double stretch) const {
    return stretch * (stiffness_ + quartic_ * stretch * stretch);
  }
  double tangent_stiffness(double stretch) const {
    return stiffness_ + 3 * quartic_ * stretch * stretch;
  }

  // ∇²_d φ(|d|) = φ''(r) n nᵀ + (φ'(r)/r)(I − n nᵀ). Negative transverse stiffness φ'/r < 0 for a
  // compressed spring (r < L) is the physics of buckling, so it is kept, not clamped.
  Block hessian_block(const Spring& spring, const Point& d) const {
    const double r = d.norm();
    const double stretch = r - spring.rest;
    const double transverse = tension(stretch) / r;
    const Point n = d / r;
    return (tangent_stiffness(stretch) - transverse) * outer(n) + transverse * Block::Identity();
  }

  // A function of q_j − q_i contributes [B −B; −B B] to the (i, j) node blocks.
  static void add_spring_blocks(const Spring& spring, const Block& block, Triplets& triplets) {
    const int i = Dim * spring.i;
    const int j = Dim * spring.j;
    for (int col = 0; col < Dim; ++col) {
      for (int row = 0; row < Dim; ++row) {
        const double value = block(row, col);
        triplets.emplace_back(i + row, i + col, value);
        triplets.emplace_back(j + row, j + col, value);
        triplets.emplace_back(i + row, j + col, -value);
        triplets.emplace_back(j + row, i + col, -value);
      }
    }
  }

  void build(const SpringNetConfig& config) {
    const int nx = config.nx, ny = config.ny, nz = config.nz;
    const auto index = [&](int ix, int iy, int iz) { return ix + nx * (iy + ny * iz); };
    // Lattice centred on the origin, so the angular momentum about the origin stays moderate.
    Vec lattice(dof());
    for (int iz = 0; iz < nz; ++iz) {
      for (int iy = 0; iy < ny; ++iy) {
        for (int ix = 0; ix < nx; ++ix) {
          const double coordinates[3] = {ix - 0.5 * (nx - 1), iy - 0.5 * (ny - 1),
                                         iz - 0.5 * (nz - 1)};
          for (int axis = 0; axis < Dim; ++axis) {
            lattice[Dim * index(ix, iy, iz) + axis] = config.spacing * coordinates[axis];
          }
        }
      }
    }

    // Neighbour offsets in {−1, 0, 1}^Dim whose first non-zero component is positive, so each
    // pair appears once: the axis springs, plus all face and body diagonals for a rigid lattice.
    std::vector<std::array<int, 3>> offsets;
    for (int oz = (Dim == 3 ? -1 : 0); oz <= (Dim == 3 ? 1 : 0); ++oz) {
      for (int oy = -1; oy <= 1; ++oy) {
        for (int ox = -1; ox <= 1; ++ox) {
          const int first_nonzero = ox != 0 ? ox : oy != 0 ? oy : oz;
          const int nonzeros = (ox != 0) + (oy != 0) + (oz != 0);
          if (first_nonzero > 0 && (config.diagonals || nonzeros == 1)) {
            offsets.push_back({ox, oy, oz});
          }
        }
      }
    }

    std::mt19937_64 generator(config.seed);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    springs_.reserve(offsets.size() * nodes_);
    for (int iz = 0; iz < nz; ++iz) {
      for (int iy = 0; iy < ny; ++iy) {
        for (int ix = 0; ix < nx; ++ix) {
          for (const auto& [ox, oy, oz] : offsets) {
            const int jx = ix + ox, jy = iy + oy, jz = iz + oz;
            if (jx < 0 || jx >= nx || jy < 0 || jy >= ny || jz < 0 || jz >= nz) continue;
            const int i = index(ix, iy, iz);
            const int j = index(jx, jy, jz);
            const double lattice_length = (point(lattice, j) - point(lattice, i)).norm();
            const double rest =
                lattice_length * (1 + config.rest_perturbation * uniform(generator));
            springs_.push_back({std::min(i, j), std::max(i, j), rest});
          }
        }
      }
    }

    // Each coordinate moves by less than half a spacing (position_jitter < ½), so along the axis
    // of the offset's first non-zero component the two ends stay apart: no zero-length spring.
    initial_.t = 0;
    initial_.q = lattice;
    for (int k = 0; k < dof(); ++k) {
      initial_.q[k] += config.position_jitter * config.spacing * uniform(generator);
    }

    // Random velocities, nothing removed, plus a drift along x and a rigid spin about the centre
    // of mass, so the total linear and angular momentum are clearly non-zero. In 3D the spin axis
    // is tilted, (1, 1, 1)/√3, so that every angular momentum component is exercised.
    Point centre = Point::Zero();
    for (int node = 0; node < nodes_; ++node) centre += point(initial_.q, node);
    centre /= nodes_;
    initial_.p.resize(dof());
    for (int node = 0; node < nodes_; ++node) {
      Point velocity;
      for (int axis = 0; axis < Dim; ++axis) velocity[axis] = config.velocity * uniform(generator);
      velocity[0] += config.drift;
      const Point arm = point(initial_.q, node) - centre;
      if constexpr (Dim == 2) {
        velocity += config.spin * Point(-arm[1], arm[0]);
      } else {
        velocity += (config.spin / std::sqrt(3.0)) * Point::Ones().cross(arm);
      }
      initial_.p.template segment<Dim>(Dim * node) = config.mass * velocity;
    }
  }

  int nodes_;
  double stiffness_;  // k
  double quartic_;    // k₄
  double damping_;    // c
  std::vector<Spring> springs_;
  State initial_;
};

}  // namespace

std::unique_ptr<Problem> make_spring_net(Params& params) {
  // Up to 10⁷ degrees of freedom: the Hessian's entry count then still fits Eigen's int indices.
  constexpr long kMaxDof = 10'000'000;
  SpringNetConfig config;
  const long dim = params.integer("dim", 2, "spatial dimension", 2, 3);
  config.nx = static_cast<int>(params.integer("nx", 8, "nodes along x", 2, kMaxDof));
  config.ny = static_cast<int>(params.integer("ny", 8, "nodes along y", 2, kMaxDof));
  config.nz =
      static_cast<int>(params.integer("nz", 1, "nodes along z (1 unless dim=3)", 1, kMaxDof));
  if (dim == 2 && config.nz != 1) {
    throw InputError(fmt::format(
        "problem 'spring_net': parameter nz={} needs dim=3 (a 2D net has nz=1)", config.nz));
  }
  if (static_cast<double>(config.nx) * config.ny * config.nz * dim > kMaxDof) {
    throw InputError(fmt::format(
        "problem 'spring_net': parameters nx={}, ny={}, nz={}, dim={} give more than {} "
        "degrees of freedom",
        config.nx, config.ny, config.nz, dim, kMaxDof));
  }
  config.spacing = params.real("spacing", 1.0, "lattice spacing", Range::above(0));
  config.mass = params.real("mass", 1.0, "mass of each node", Range::above(0));
  config.stiffness = params.real("stiffness", 100.0, "spring stiffness k", Range::above(0));
  const std::string model = params.choice("model", "hookean", {"hookean", "nonlinear"},
                                          "spring law: 1/2 k (r-L)^2, or plus 1/4 k4 (r-L)^4");
  const double quartic = params.real(
      "quartic", 10 * config.stiffness,
      "quartic coefficient k4 (model=nonlinear only; default 10*stiffness)", Range::at_least(0));
  config.quartic = model == "nonlinear" ? quartic : 0.0;
  config.diagonals = params.flag("diagonals", true, "add face/body diagonal springs (rigid)");
  config.rest_perturbation =
      params.real("rest_perturbation", 0.1, "relative random perturbation of the rest lengths",
                  Range::closed_open(0, 1));
  config.position_jitter =
      params.real("position_jitter", 0.05, "random initial displacement relative to spacing",
                  Range::closed_open(0, 0.5));
  config.velocity =
      params.real("velocity", 1.0, "scale of the random initial velocities", Range::at_least(0));
  config.spin = params.real("spin", 0.5, "angular velocity of a rigid spin about the centre");
  config.drift = params.real("drift", 0.3, "uniform initial velocity along x");
  config.seed = static_cast<unsigned long>(
      params.integer("seed", 1, "random seed (std::mt19937_64)", 0, 1L << 62));
  config.damping =
      params.real("damping", 0.0, "damping coefficient c along the springs", Range::at_least(0));
  if (dim == 2) return std::make_unique<SpringNet<2>>(config);
  return std::make_unique<SpringNet<3>>(config);
}

}  // namespace geomint
