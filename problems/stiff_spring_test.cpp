// Checks of the two-scale stiff spring beyond the registry suite: the normal-mode frequencies
// against the characteristic polynomial in long double up to ratio 1e8, and how little the stiff
// spring stretches when only the slow mode is excited.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "problems/problem.hpp"

namespace geomint {
namespace stiff_spring_test {
namespace {

TEST(StiffSpring, FrequenciesSolveTheCharacteristicPolynomial) {
  // det(K − λM) = m²λ² − m(k_s + 2k_f)λ + k_s k_f = 0; roots in long double, the small one via
  // the product of the roots (no cancellation).
  for (double ratio : {1.0, 1e4, 1e8}) {
    const long double ks = 2.5L, kf = 2.5L * ratio, m = 0.3L;
    const long double b = ks + 2 * kf;
    const long double big = (b + std::sqrt(b * b - 4 * ks * kf)) / (2 * m);
    const long double small = ks * kf / (m * m * big);
    const auto problem =
        make_problem("stiff_spring:k_soft=2.5,mass=0.3,ratio=" + format_number(ratio));
    const double fast = std::sqrt(static_cast<double>(big));
    EXPECT_NEAR(problem->omega_max(problem->initial_state().q), fast, 1e-14 * fast) << ratio;
    // Started on the slow mode's shape, (K − λM)v = 0 ⇒ v₂/v₁ = (k_s + k_f − mλ)/k_f, it moves as
    // q(t) = q(0) cos(ω_slow t) without exciting the fast mode.
    const double stretch = static_cast<double>((ks - m * small) / kf);
    const auto slow_only =
        make_problem("stiff_spring:k_soft=2.5,mass=0.3,ratio=" + format_number(ratio) +
                     ",stretch=" + format_number(stretch));
    const double slow = std::sqrt(static_cast<double>(small));
    const State start = slow_only->initial_state();
    for (double t : {0.37, 5.1, 123.4}) {
      const State state = slow_only->exact(t);
      for (int i = 0; i < 2; ++i) {
        EXPECT_NEAR(state.q[i], start.q[i] * std::cos(slow * t), 1e-12) << ratio << " t " << t;
        EXPECT_NEAR(state.p[i], -0.3 * slow * start.q[i] * std::sin(slow * t), 1e-12) << ratio;
      }
    }
  }
}

TEST(StiffSpring, StiffSpringBarelyStretchesWhenOnlyTheSlowModeIsExcited) {
  // From rest with both masses displaced by 1 the stiff spring stretches by at most
  // ~2 k_s/k_f (quasi-static load k_s q₁ on it, doubled by the sudden release).
  for (double ratio : {1e4, 1e8}) {
    const auto problem = make_problem("stiff_spring:ratio=" + format_number(ratio));
    double largest = 0;
    for (int k = 0; k <= 2000; ++k) {
      const State state = problem->exact(k * 0.0731);
      largest = std::max(largest, std::abs(state.q[1] - state.q[0]));
    }
    EXPECT_LE(largest, 2.5 / ratio) << ratio;
    EXPECT_GT(largest, 0.5 / ratio) << ratio;
  }
  EXPECT_THROW(make_problem("stiff_spring:ratio=0.5"), InputError);
  EXPECT_THROW(make_problem("stiff_spring:k_soft=0"), InputError);
}

}  // namespace
}  // namespace stiff_spring_test
}  // namespace geomint
