// The exact motion of the planar pendulum θ̈ = −ω0² sin θ through Jacobi elliptic functions
// (DLMF §22.19(i)), shared by `pendulum` (angle coordinate) and `cartesian_pendulum` (the same
// motion on a rod, docs/METHOD.md §3).
#pragma once

namespace geomint {

class PendulumMotion {
 public:
  PendulumMotion(double theta0, double omega0, double v0);

  // Off the separatrix (and more than k' ~ 1e-10 away from it) the motion has a closed form.
  bool has_exact() const { return has_exact_; }
  bool librating() const { return librating_; }
  struct Angle {
    double theta, theta_dot;
  };
  // θ(t) and θ̇(t). Only when has_exact().
  Angle at(double t) const;
  // Libration: 4K(k)/ω0; rotation: the time of one revolution. Only when has_exact().
  double period() const;

 private:
  double omega0_;
  double modulus_ = 0;  // k = √(E / 2ω0²); the motion librates iff k < 1
  bool librating_ = false;
  bool has_exact_ = false;
  // Parameter m of the elliptic functions (k² librating, 1/k² rotating) and m' = 1 − m.
  double parameter_ = 0, complementary_parameter_ = 1;
  double quarter_period_ = 0;  // K(m)
  double phase0_ = 0;          // u0
  double direction_ = 1;       // sign of the rotation
  double turns_offset_ = 0;    // θ0 minus its representative in [−π, π]
};

}  // namespace geomint
