// Gravitational N-body problem in the plane or in space, H = ½ Σ |p_i|²/m_i − G Σ_{i<j} m_i m_j /
// |q_i − q_j| (GNI §I.2.4), from parameters, a CSV file or a preset: the IVP Test Set's Pleiades
// ("plei", Mazzia & Magherini, release 2.4) and GNI Table 2.1's outer solar system, which the
// problem `outer_solar_system` is an alias of (one implementation, docs/DESIGN.md §2).
#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "problems/problem.hpp"
#include "problems/structures/kepler_orbit.hpp"

namespace geomint {
namespace {

// Bodies as flat arrays: `dim` coordinates per body in positions and velocities.
struct NBodyData {
  int dim = 3;
  double gravity = 1.0;
  std::vector<double> masses;
  std::vector<double> positions;
  std::vector<double> velocities;
  double dt = 0.01;
  double t_end = 10.0;
  // A tabulated solution (positions, velocities) at reference_t (kEndReference) when non-empty.
  double reference_t = 0.0;
  std::vector<double> reference_positions, reference_velocities;
};

// GNI Table 2.1: the Sun (with the inner planets' masses), Jupiter, Saturn, Uranus, Neptune,
// Pluto on 5 September 1994, 0h00 GST; AU, days, solar masses, G in AU³/(solar mass · day²).
constexpr double kSolarGravity = 2.95912208286e-4;
struct SolarBody {
  double mass;
  std::array<double, 3> position;
  std::array<double, 3> velocity;
};
constexpr std::array<SolarBody, 6> kOuterSolarSystem = {{
    {1.00000597682, {0, 0, 0}, {0, 0, 0}},
    {0.000954786104043,
     {-3.5023653, -3.8169847, -1.5507963},
     {0.00565429, -0.00412490, -0.00190589}},
    {0.000285583733151, {9.0755314, -3.0458353, -1.6483708}, {0.00168318, 0.00483525, 0.00192462}},
    {0.0000437273164546,
     {8.3101420, -16.2901086, -7.2521278},
     {0.00354178, 0.00137102, 0.00055029}},
    {0.0000517759138449,
     {11.4707666, -25.7294829, -10.8169456},
     {0.00288930, 0.00114527, 0.00039677}},
    {1 / 1.3e8, {-15.5387357, -25.2225594, -3.1902382}, {0.00276725, -0.00170702, -0.00136504}},
}};

NBodyData outer_solar_system_data(int planets) {
  NBodyData data;
  data.dim = 3;
  data.gravity = kSolarGravity;
  for (int b = 0; b <= planets; ++b) {
    const SolarBody& body = kOuterSolarSystem[b];
    data.masses.push_back(body.mass);
    data.positions.insert(data.positions.end(), body.position.begin(), body.position.end());
    data.velocities.insert(data.velocities.end(), body.velocity.begin(), body.velocity.end());
  }
  // GNI's step and horizon for Fig. 2.4 ff.: h = 10 days (Jupiter's period is ~4332 days),
  // 200 000 days.
  data.dt = 10.0;
  data.t_end = 200'000.0;
  return data;
}

// The Test Set's "plei" (problem description plei.pdf, release 2.4): seven stars in the plane,
// m_i = i, G = 1, t ∈ [0, 3]; (x, y, ẋ, ẏ) at t = 0 as tabulated there.
NBodyData pleiades_data() {
  NBodyData data;
  data.dim = 2;
  data.gravity = 1.0;
  const std::array<double, 7> x = {3, 3, -1, -3, 2, -2, 2};
  const std::array<double, 7> y = {3, -3, 2, 0, 0, -4, 4};
  const std::array<double, 7> u = {0, 0, 0, 0, 0, 1.75, -1.5};
  const std::array<double, 7> v = {0, 0, 0, -1.25, 1, 0, 0};
  for (int i = 0; i < 7; ++i) {
    data.masses.push_back(i + 1);
    data.positions.insert(data.positions.end(), {x[i], y[i]});
    data.velocities.insert(data.velocities.end(), {u[i], v[i]});
  }
  // The closest encounters come within ~0.1 at speeds ~10: h = 1e-3 resolves them.
  data.dt = 1e-3;
  data.t_end = 3.0;
  // The Test Set's reference at t = 3 (plei.f, subroutine solut), in its order (x1…x7, y1…y7,
  // ẋ1…ẋ7, ẏ1…ẏ7); integrators/nbody_reference_test.cpp keeps an independent copy.
  constexpr double kReference[28] = {
      0.3706139143970502,  3.237284092057233,   -3.222559032418324,  0.6597091455775310,
      0.3425581707156584,  1.562172101400631,   -0.7003092922212495, -3.943437585517392,
      -3.271380973972550,  5.225081843456543,   -2.590612434977470,  1.198213693392275,
      -0.2429682344935824, 1.091449240428980,   3.417003806314313,   1.354584501625501,
      -2.590065597810775,  2.025053734714242,   -1.155815100160448,  -0.8072988170223021,
      0.5952396354208710,  -3.741244961234010,  0.3773459685750630,  0.9386858869551073,
      0.3667922227200571,  -0.3474046353808490, 2.344915448180937,   -1.947020434263292};
  data.reference_t = 3.0;
  for (int i = 0; i < 7; ++i) {
    data.reference_positions.insert(data.reference_positions.end(),
                                    {kReference[i], kReference[7 + i]});
    data.reference_velocities.insert(data.reference_velocities.end(),
                                     {kReference[14 + i], kReference[21 + i]});
  }
  return data;
}

// Moves to the centre-of-mass frame: Σ m_i q_i = 0 and Σ m_i v_i = 0.
void to_centre_of_mass_frame(NBodyData& data) {
  const int bodies = static_cast<int>(data.masses.size());
  double total = 0;
  for (double m : data.masses) total += m;
  for (std::vector<double>* values : {&data.positions, &data.velocities}) {
    for (int k = 0; k < data.dim; ++k) {
      double weighted = 0;
      for (int b = 0; b < bodies; ++b) weighted += data.masses[b] * (*values)[data.dim * b + k];
      for (int b = 0; b < bodies; ++b) (*values)[data.dim * b + k] -= weighted / total;
    }
  }
}

template <int Dim>
class NBody final : public Problem, public KeplerOrbitStructure {
 public:
  using Point = Eigen::Matrix<double, Dim, 1>;

  explicit NBody(const NBodyData& data)
      : bodies_(static_cast<int>(data.masses.size())),
        gravity_(data.gravity),
        masses_(data.masses) {
    Vec mass(Dim * bodies_);
    initial_.q.resize(Dim * bodies_);
    initial_.p.resize(Dim * bodies_);
    for (int b = 0; b < bodies_; ++b) {
      for (int k = 0; k < Dim; ++k) {
        mass[Dim * b + k] = masses_[b];
        initial_.q[Dim * b + k] = data.positions[Dim * b + k];
        initial_.p[Dim * b + k] = masses_[b] * data.velocities[Dim * b + k];
      }
    }
    set_mass(mass);
    // Gravity depends on differences only: total linear and angular momentum are conserved.
    unsigned capabilities = kHessian | kLinearMomentum | kAngularMomentum | kOmegaMax;
    if (!data.reference_positions.empty()) {
      capabilities |= kEndReference;
      reference_.t = data.reference_t;
      reference_.q = Eigen::Map<const Vec>(data.reference_positions.data(), Dim * bodies_);
      reference_.p =
          mass.cwiseProduct(Eigen::Map<const Vec>(data.reference_velocities.data(), Dim * bodies_));
    }
    set_capabilities(capabilities);
    set_defaults(data.dt, data.t_end);
  }

  State initial_state() const override { return initial_; }
  double end_reference_time() const override { return reference_.t; }
  State end_reference() const override { return reference_; }

  double potential(const Vec& q) const override {
    double sum = 0;
    for (int i = 0; i < bodies_; ++i) {
      for (int j = i + 1; j < bodies_; ++j) {
        sum -= gravity_ * masses_[i] * masses_[j] / (body(q, i) - body(q, j)).norm();
      }
    }
    return sum;
  }

  // ∂/∂q_i of −c/|q_i − q_j| is c (q_i − q_j)/r³; body j gets the opposite. The operation order
  // is the one the committed outer_solar_system results were computed with.
  void gradient(const Vec& q, Vec& g) const override {
    g.setZero(Dim * bodies_);
    for (int i = 0; i < bodies_; ++i) {
      for (int j = i + 1; j < bodies_; ++j) {
        const Point d = body(q, i) - body(q, j);
        const double r = d.norm();
        const Point pull = (gravity_ * masses_[i] * masses_[j] / (r * r * r)) * d;
        g.template segment<Dim>(Dim * i) += pull;
        g.template segment<Dim>(Dim * j) -= pull;
      }
    }
  }

  // Pair block B = c (I/r³ − 3 d dᵀ/r⁵) on the diagonal blocks of i and j, −B off the diagonal.
  void hessian(const Vec& q, SparseMatrix& H) const override {
    using Block = Eigen::Matrix<double, Dim, Dim>;
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(4 * Dim * Dim * bodies_ * bodies_);
    for (int i = 0; i < bodies_; ++i) {
      for (int j = i + 1; j < bodies_; ++j) {
        const Point d = body(q, i) - body(q, j);
        const double r = d.norm();
        const double c = gravity_ * masses_[i] * masses_[j];
        const Block block =
            (c / (r * r * r)) * (Block::Identity() - (3 / (r * r)) * d * d.transpose());
        for (int a = 0; a < Dim; ++a) {
          for (int b = 0; b < Dim; ++b) {
            triplets.emplace_back(Dim * i + a, Dim * i + b, block(a, b));
            triplets.emplace_back(Dim * j + a, Dim * j + b, block(a, b));
            triplets.emplace_back(Dim * i + a, Dim * j + b, -block(a, b));
            triplets.emplace_back(Dim * j + a, Dim * i + b, -block(a, b));
          }
        }
      }
    }
    H.resize(Dim * bodies_, Dim * bodies_);
    H.setFromTriplets(triplets.begin(), triplets.end());
  }

  Vec linear_momentum(const Vec&, const Vec& p) const override {
    Point total = Point::Zero();
    for (int b = 0; b < bodies_; ++b) total += body(p, b);
    return total;
  }

  // Σ q_i × p_i: three components in space, the one normal to the plane in 2D.
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    if constexpr (Dim == 3) {
      Point total = Point::Zero();
      for (int b = 0; b < bodies_; ++b) total += body(q, b).cross(body(p, b));
      return total;
    } else {
      double total = 0;
      for (int b = 0; b < bodies_; ++b) {
        total += q[2 * b] * p[2 * b + 1] - q[2 * b + 1] * p[2 * b];
      }
      return Vec::Constant(1, total);
    }
  }

  // Two bodies move on a Kepler orbit relative to each other; more do not.
  const void* structure(const StructureKey& key) const override {
    if (bodies_ == 2) {
      if (auto* s = offer<KeplerOrbitStructure>(key, this)) return s;
    }
    return Problem::structure(key);
  }
  // x = x₂ − x₁, v = p₂/m₂ − p₁/m₁, μ = G(m₁ + m₂).
  Eigen::Vector3d eccentricity_vector(const Vec& q, const Vec& p) const override {
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
    x.template head<Dim>() = body(q, 1) - body(q, 0);
    v.template head<Dim>() = body(p, 1) / masses_[1] - body(p, 0) / masses_[0];
    return geomint::eccentricity_vector(x, v, gravity_ * (masses_[0] + masses_[1]));
  }

  // The second body's first coordinate relative to the centre of mass, which moves uniformly in
  // the given frame: in a two-body problem it crosses 0 upwards once per orbit; in the outer
  // solar system it is Jupiter's.
  double period_observable(const Vec& q, const Vec&) const override {
    double weighted = 0, total = 0;
    for (int b = 0; b < bodies_; ++b) {
      weighted += masses_[b] * q[Dim * b];
      total += masses_[b];
    }
    return q[Dim] - weighted / total;
  }

  // Gershgorin bound on the eigenvalues of M⁻¹∇²V (similar to M^(−½)∇²V M^(−½)): the largest
  // absolute row sum divided by the row's mass.
  double omega_max(const Vec& q) const override {
    SparseMatrix H;
    hessian(q, H);
    const Eigen::MatrixXd dense(H);
    const Vec rows = dense.cwiseAbs().rowwise().sum();
    return std::sqrt(rows.cwiseProduct(inverse_mass()).maxCoeff());
  }

 private:
  static Point body(const Vec& x, int b) { return x.template segment<Dim>(Dim * b); }

  int bodies_;
  double gravity_;
  std::vector<double> masses_;
  State initial_;
  State reference_;  // kEndReference (Pleiades in the given frame)
};

std::unique_ptr<Problem> build(const NBodyData& data) {
  if (data.dim == 2) return std::make_unique<NBody<2>>(data);
  return std::make_unique<NBody<3>>(data);
}

// m,x,y[,z],vx,vy[,vz] per line (5 columns in the plane, 7 in space); a first line that does
// not parse as numbers is a header; blank lines and lines starting with '#' are skipped.
NBodyData read_bodies_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("problem 'nbody': parameter file='" + path + "' cannot be read");
  NBodyData data;
  data.dim = 0;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) {
      continue;
    }
    std::vector<double> row;
    bool numeric = true;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) {
      char* end = nullptr;
      const double value = std::strtod(field.c_str(), &end);
      while (end && (*end == ' ' || *end == '\t' || *end == '\r')) ++end;
      numeric = numeric && end != field.c_str() && *end == '\0' && std::isfinite(value);
      row.push_back(value);
    }
    if (!numeric) {
      if (data.masses.empty() && data.dim == 0 && line_number == 1) continue;  // header
      throw InputError("problem 'nbody': " + path + ":" + std::to_string(line_number) +
                       ": not a row of finite numbers m,x,y[,z],vx,vy[,vz]");
    }
    const int dim = row.size() == 5 ? 2 : row.size() == 7 ? 3 : 0;
    if (dim == 0 || (data.dim != 0 && dim != data.dim)) {
      throw InputError("problem 'nbody': " + path + ":" + std::to_string(line_number) + ": " +
                       std::to_string(row.size()) +
                       " columns; expected 5 (m,x,y,vx,vy) or 7 (m,x,y,z,vx,vy,vz) on every row");
    }
    data.dim = dim;
    data.masses.push_back(row[0]);
    data.positions.insert(data.positions.end(), row.begin() + 1, row.begin() + 1 + dim);
    data.velocities.insert(data.velocities.end(), row.begin() + 1 + dim, row.end());
  }
  if (data.masses.empty()) throw InputError("problem 'nbody': " + path + " lists no bodies");
  return data;
}

void check_bodies(const NBodyData& data) {
  if (data.masses.size() < 2) {
    throw InputError("problem 'nbody': needs at least 2 bodies, got " +
                     std::to_string(data.masses.size()));
  }
  for (double m : data.masses) {
    if (!(m > 0)) throw InputError("problem 'nbody': every mass must be > 0");
  }
  const int n = static_cast<int>(data.masses.size());
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      bool same = true;
      for (int k = 0; k < data.dim; ++k) {
        same = same && data.positions[data.dim * i + k] == data.positions[data.dim * j + k];
      }
      if (same) {
        throw InputError("problem 'nbody': bodies " + std::to_string(i + 1) + " and " +
                         std::to_string(j + 1) + " start at the same position");
      }
    }
  }
}

}  // namespace

std::unique_ptr<Problem> make_nbody(Params& params) {
  const std::string preset =
      params.choice("preset", "pleiades", {"pleiades", "outer_solar_system", "custom"},
                    "initial data: IVP Test Set Pleiades, GNI outer solar system, or custom "
                    "(masses/positions/velocities or file)");
  NBodyData data;
  if (preset == "pleiades") {
    data = pleiades_data();
  } else if (preset == "outer_solar_system") {
    data = outer_solar_system_data(static_cast<int>(params.integer(
        "planets", 5, "number of planets from Jupiter outwards (5 = up to Pluto)", 1, 5)));
  } else {
    const std::string file = params.text(
        "file", "", "CSV of bodies m,x,y[,z],vx,vy[,vz] (instead of masses/positions/velocities)");
    if (!file.empty()) {
      data = read_bodies_csv(file);
    } else {
      data.dim = static_cast<int>(params.integer("dim", 2, "spatial dimension", 2, 3));
      data.masses = params.reals("masses", "masses m1/m2/…");
      data.positions = params.reals("positions", "positions, dim per body: x1/y1[/z1]/x2/…");
      data.velocities = params.reals("velocities", "velocities, dim per body (default 0)");
      if (data.velocities.empty()) data.velocities.assign(data.positions.size(), 0.0);
      const size_t expected = data.dim * data.masses.size();
      if (data.masses.empty() || data.positions.size() != expected ||
          data.velocities.size() != expected) {
        throw InputError(
            "problem 'nbody': preset=custom needs masses=m1/m2/… and positions (and "
            "optionally velocities) with dim = " +
            std::to_string(data.dim) + " entries per body: " + std::to_string(data.masses.size()) +
            " masses need " + std::to_string(expected) + " positions, got " +
            std::to_string(data.positions.size()) + " and velocities " +
            std::to_string(data.velocities.size()) + "; or file=bodies.csv");
      }
    }
    data.gravity = params.real("G", 1.0, "gravitational constant", Range::above(0));
    check_bodies(data);
  }
  if (params.choice(
          "frame", "given", {"given", "com"},
          "coordinates as given, or moved to the centre-of-mass frame (Σ m q = Σ m v = 0)") ==
      "com") {
    to_centre_of_mass_frame(data);
    // The tabulated solution is in the given frame.
    data.reference_positions.clear();
    data.reference_velocities.clear();
  }
  return build(data);
}

// The GNI outer solar system, the same problem as nbody:preset=outer_solar_system.
std::unique_ptr<Problem> make_outer_solar_system(Params& params) {
  const int planets = static_cast<int>(params.integer(
      "planets", 5, "number of planets from Jupiter outwards (5 = up to Pluto)", 1, 5));
  return build(outer_solar_system_data(planets));
}

}  // namespace geomint
