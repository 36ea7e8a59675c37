// The planar hinge chain that `pendulum`, `double_pendulum` and `rod_chain:coordinates=joint` are
// (point masses on massless rods from a fixed pivot, gravity down), read from the problem's own
// spec, and the maps between the problem's state (absolute angles θ, p) and an engine's joints.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/problem.hpp"

namespace geomint::engines {

struct PlanarChain {
  std::vector<double> mass;    // point mass at the end of rod i
  std::vector<double> length;  // rod i, from node i − 1 (the pivot for i = 0) to node i
  double gravity = 0;          // acceleration along the downward vertical
  int links() const { return static_cast<int>(mass.size()); }
};

// The problems a chain engine runs, for refusals and docs ("pendulum, double_pendulum, ...").
const std::vector<std::string>& chain_problem_specs();

// The chain `problem` is, from its canonical spec (every parameter written out, so nothing here
// repeats a default), or nullopt with `why` saying why it is none.
std::optional<PlanarChain> planar_chain_of(const Problem& problem, std::string& why);

// Joint angles of an engine chain are relative (φ₁ = θ₁, φᵢ = θᵢ − θᵢ₋₁); the problem's are
// absolute from the downward vertical (θᵢ = φ₁ + … + φᵢ). The same maps hold for rates.
void absolute_to_relative(const Vec& absolute, Vec& relative);
void relative_to_absolute(const Vec& relative, Vec& absolute);

// θ̇ = M(θ)⁻¹p and p = M(θ)θ̇ through the problem's own mass: its LagrangianSystem where it is
// one (M(θ)), its constant diagonal mass otherwise (the pendulum).
Vec chain_velocity(const Problem& problem, const Vec& q, const Vec& p);
Vec chain_momentum(const Problem& problem, const Vec& q, const Vec& v);

}  // namespace geomint::engines
