// Gradients of the few-dof problems as inlineable functors, shared by their Problem::gradient and
// by the statically typed step loops of the explicit methods (docs/DESIGN.md §2).
// One formula per problem, templated on the vector type, so both paths round identically.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <variant>

namespace geomint {

// Kepler V = −1/|q| (problems/kepler.cpp): ∇V = q/|q|³.
struct KeplerGradient {
  static constexpr int kDof = 2;
  template <class In, class Out>
  void operator()(const In& q, Out& g) const {
    const double r = q.norm();
    g = q / (r * r * r);
  }
};

// Harmonic oscillator V = ½kq² (problems/harmonic.cpp), k = mω².
struct HarmonicGradient {
  static constexpr int kDof = 1;
  double stiffness = 0;
  template <class In, class Out>
  void operator()(const In& q, Out& g) const {
    g.resize(1);
    g[0] = stiffness * q[0];
  }
};

// Pendulum V = ω₀²(1 − cos θ) (problems/pendulum.cpp): ∇V = ω₀² sin θ.
struct PendulumGradient {
  static constexpr int kDof = 1;
  double omega0 = 0;
  template <class In, class Out>
  void operator()(const In& q, Out& g) const {
    g.resize(1);
    g[0] = omega0 * omega0 * std::sin(q[0]);
  }
};

// Hénon–Heiles V = ½(x² + y²) + x²y − y³/3 (problems/henon_heiles.cpp).
struct HenonHeilesGradient {
  static constexpr int kDof = 2;
  template <class In, class Out>
  void operator()(const In& q, Out& g) const {
    g.resize(2);
    g << q[0] + 2 * q[0] * q[1], q[1] + q[0] * q[0] - q[1] * q[1];
  }
};

// What Problem::fixed_gradient() offers: nothing (std::monostate, the default) or one of the
// functors above. Explicit methods visit it once per run and instantiate their step loop with
// the functor inlined on fixed-size vectors; a new few-dof problem adds its functor here.
using FixedGradient = std::variant<std::monostate, KeplerGradient, HarmonicGradient,
                                   PendulumGradient, HenonHeilesGradient>;

}  // namespace geomint
