// A planar chain of n rigid rods hanging from a fixed pivot under gravity (−y), in Cartesian node
// coordinates x_1 … x_n (2n dof) with one length constraint per rod (docs/METHOD.md §3;
// problems/rods.hpp): n = 1 is the Cartesian pendulum, n = 2 the (chaotic) double pendulum.
#include <fmt/format.h>

#include <cmath>

#include "problems/problem.hpp"
#include "problems/rods.hpp"

namespace geomint {
namespace {

class RodChain final : public rods::RodProblem {
 public:
  RodChain(const Vec& node_mass, std::vector<rods::Rod> chain, double gravity, State initial)
      : RodProblem(std::move(chain), 2), gravity_(gravity), initial_(std::move(initial)) {
    Vec mass(2 * node_mass.size());
    for (int i = 0; i < node_mass.size(); ++i) mass.segment(2 * i, 2).setConstant(node_mass[i]);
    set_mass(mass);
    // The pivot is not a degree of freedom, so nothing is translation or rotation invariant:
    // no momentum capability; the motion is chaotic for n >= 2, so no exact solution either.
    set_capabilities(kHessian | kConstraints);
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

}  // namespace

std::unique_ptr<Problem> make_rod_chain(Params& params) {
  const auto positive = [](double x) { return x > 0; };
  const int n =
      static_cast<int>(params.integer("n", 2, "number of rods (and moving nodes)", 1, 64));
  const double mass = params.real("mass", 1.0, "mass of node 1", positive, "> 0");
  const double mass_ratio =
      params.real("mass_ratio", 1.0, "mass of node i+1 / mass of node i", positive, "> 0");
  const double length = params.real("length", 1.0, "length of rod 1", positive, "> 0");
  const double length_ratio =
      params.real("length_ratio", 1.0, "length of rod i+1 / length of rod i", positive, "> 0");
  const double gravity =
      params.real("gravity", 1.0, "gravitational acceleration (along -y)", positive, "> 0");
  const auto angle_ok = [](double x) { return std::abs(x) <= 1000; };
  const double theta = params.real("theta", 2.0,
                                   "initial angle of every rod from the downward vertical (rad); "
                                   "theta<i> overrides it for rod i",
                                   angle_ok, "|theta| <= 1000");
  const double omega =
      params.real("omega", 0.0, "initial angular velocity of every rod (rad per time unit)");
  Vec node_mass(n);
  std::vector<rods::Rod> chain;
  State initial{0.0, Vec(2 * n), Vec(2 * n)};
  // Build the state from the angles, node by node from the pivot: every rod has its length and
  // every relative velocity is perpendicular to its rod, so the state is consistent by
  // construction (make_problem still checks it).
  double x = 0, y = 0, vx = 0, vy = 0;
  for (int i = 0; i < n; ++i) {
    const double angle = params.real(fmt::format("theta{}", i + 1), theta,
                                     fmt::format("initial angle of rod {} (rad)", i + 1), angle_ok,
                                     "|theta<i>| <= 1000");
    const double rod_length = length * std::pow(length_ratio, i);
    node_mass[i] = mass * std::pow(mass_ratio, i);
    if (!std::isfinite(rod_length) || !std::isfinite(node_mass[i]) || rod_length <= 0 ||
        node_mass[i] <= 0) {
      throw InputError(fmt::format(
          "problem 'rod_chain': mass_ratio or length_ratio give a non-positive or non-finite "
          "mass or length at node {} of {}",
          i + 1, n));
    }
    chain.push_back({i == 0 ? rods::kPivot : i - 1, i, rod_length});
    x += rod_length * std::sin(angle);
    y -= rod_length * std::cos(angle);
    vx += rod_length * omega * std::cos(angle);
    vy += rod_length * omega * std::sin(angle);
    initial.q.segment(2 * i, 2) << x, y;
    initial.p.segment(2 * i, 2) << node_mass[i] * vx, node_mass[i] * vy;
  }
  return std::make_unique<RodChain>(node_mass, std::move(chain), gravity, std::move(initial));
}

}  // namespace geomint
