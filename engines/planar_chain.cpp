// Planar hinge chains from the problems' specs (engines/planar_chain.hpp).
#include "engines/planar_chain.hpp"

#include <fmt/format.h>

#include <cmath>

#include "problems/lagrangian.hpp"

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

}  // namespace

const std::vector<std::string>& chain_problem_specs() {
  static const std::vector<std::string> specs = {"pendulum", "double_pendulum",
                                                 "rod_chain:coordinates=joint"};
  return specs;
}

std::optional<PlanarChain> planar_chain_of(const Problem& problem, std::string& why) {
  const Spec spec = Spec::parse(problem.spec());
  PlanarChain chain;
  if (spec.name == "pendulum") {
    // θ̈ = −ω₀² sin θ with the problem's mass m: a point mass m on a rod of length 1 under
    // g = ω₀² (the potential m g l (1 − cos θ) per unit mass is ω₀²(1 − cos θ)).
    chain.mass = {problem.mass()[0]};
    chain.length = {1.0};
    const double omega0 = spec_real(spec, "omega0");
    chain.gravity = omega0 * omega0;
    return chain;
  }
  if (spec.name == "double_pendulum") {
    chain.mass = {spec_real(spec, "m1"), spec_real(spec, "m2")};
    chain.length = {spec_real(spec, "l1"), spec_real(spec, "l2")};
    chain.gravity = spec_real(spec, "g");
    return chain;
  }
  if (spec.name == "rod_chain" && spec.values.count("coordinates") &&
      spec.values.at("coordinates") == "joint") {
    // Node masses and rod lengths as make_rod_chain forms them (the fidelity tests compare the
    // resulting mass matrix and potential with the problem's own).
    const int n = static_cast<int>(spec_real(spec, "n"));
    for (int i = 0; i < n; ++i) {
      chain.mass.push_back(spec_real(spec, "mass") * std::pow(spec_real(spec, "mass_ratio"), i));
      chain.length.push_back(spec_real(spec, "length") *
                             std::pow(spec_real(spec, "length_ratio"), i));
    }
    chain.gravity = spec_real(spec, "gravity");
    return chain;
  }
  why = spec.name == "rod_chain"
            ? "rod_chain in Cartesian node coordinates is a constrained system; the engine runs "
              "it in joint angles (rod_chain:coordinates=joint)"
            : fmt::format("problem '{}' is no planar hinge chain", spec.name);
  return std::nullopt;
}

void absolute_to_relative(const Vec& absolute, Vec& relative) {
  relative.resize(absolute.size());
  for (Eigen::Index i = 0; i < absolute.size(); ++i) {
    relative[i] = i == 0 ? absolute[0] : absolute[i] - absolute[i - 1];
  }
}

void relative_to_absolute(const Vec& relative, Vec& absolute) {
  absolute.resize(relative.size());
  double sum = 0;
  for (Eigen::Index i = 0; i < relative.size(); ++i) absolute[i] = sum += relative[i];
}

Vec chain_velocity(const Problem& problem, const Vec& q, const Vec& p) {
  if (const LagrangianSystem* lagrangian = problem.as_lagrangian()) {
    return lagrangian->velocity(q, p);
  }
  return problem.inverse_mass().cwiseProduct(p);
}

Vec chain_momentum(const Problem& problem, const Vec& q, const Vec& v) {
  if (const LagrangianSystem* lagrangian = problem.as_lagrangian()) {
    // Through the problem's mass operator, not the dense M(θ): the joint chain's is an O(n)
    // recursion, and this runs after every engine step (docs/ENGINES.md "Adapter overhead").
    Vec p;
    lagrangian->apply_mass(q, v, p);
    Vec a;
    lagrangian->gyroscopic(q, a);
    return p + a;
  }
  return problem.mass().cwiseProduct(v);
}

}  // namespace geomint::engines
