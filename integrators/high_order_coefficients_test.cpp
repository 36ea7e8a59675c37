// Order, symplecticity and symmetry conditions of every high-order coefficient table
// (high_order_coefficients.hpp), in long double: Runge–Kutta trees (Butcher; GNI §III.1–III.2),
// simplifying assumptions B, C, D (Butcher 1964), symplecticity (GNI §VI.4), and the conditions of
// symmetric compositions through the Baker–Campbell–Hausdorff expansion (GNI §III.4, §V.3.2).
#include "integrators/high_order_coefficients.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace geomint {
namespace high_order_coefficients_test {
namespace {

using Real = long double;
using coefficients::PartitionedTableau;

// The tables are exact to ~1e-19 (long double) or to the 26 published digits; every condition
// below sums at most ~1e4 products of coefficients of size ≤ 2, so 1e-16 (half a double ulp)
// separates a satisfied condition from a wrong digit.
constexpr Real kTolerance = 1e-16L;
// A condition that fails by more than this is violated, not merely rounded.
constexpr Real kViolated = 1e-8L;

// ---------------------------------------------------------------------------------------------
// Runge–Kutta order conditions on rooted trees.
//
// A tree with n vertices is enumerated as a recursive tree: parent[v] < v for v ≥ 1 (every
// rooted tree shape appears, some several times, which does not matter for a check). Partitioned
// methods need bicoloured trees (GNI §III.2.1): a vertex of colour 0 is a q-derivative, reached
// from its parent through a_ij; colour 1 a p-derivative, through â_ij. The condition is
// Φ(t) = Σ_i b_i Π… = 1/γ(t), γ(t) = Π_v |subtree(v)| (GNI §III.1.3 and §III.2.1).

struct TreeCheck {
  Real worst = 0;  // max |Φ(t) − 1/γ(t)| over trees of this order
  std::string worst_tree;
};

TreeCheck check_trees(const PartitionedTableau& tableau, int order) {
  const int s = tableau.stages;
  TreeCheck check;
  std::vector<int> parent(order, -1);
  const std::function<void(int)> grow = [&](int vertex) {
    if (vertex == order) {
      std::vector<int> size(order, 1);
      for (int v = order - 1; v >= 1; --v) size[parent[v]] += size[v];
      Real gamma = 1;
      for (int v = 0; v < order; ++v) gamma *= size[v];
      for (unsigned colours = 0; colours < (1u << order); ++colours) {
        // w[v][i]: product over v's subtrees of their stage sums, children before parents.
        std::vector<std::vector<Real>> w(order, std::vector<Real>(s, 1.0L));
        for (int v = order - 1; v >= 1; --v) {
          const auto& coefficient = ((colours >> v) & 1u) ? tableau.a_hat : tableau.a;
          for (int i = 0; i < s; ++i) {
            Real sum = 0;
            for (int j = 0; j < s; ++j) sum += coefficient[i][j] * w[v][j];
            w[parent[v]][i] *= sum;
          }
        }
        Real phi = 0;
        for (int i = 0; i < s; ++i) phi += tableau.b[i] * w[0][i];
        const Real defect = std::fabs(phi - 1 / gamma);
        if (defect > check.worst) {
          check.worst = defect;
          check.worst_tree = "parents";
          for (int v = 1; v < order; ++v) check.worst_tree += " " + std::to_string(parent[v]);
          check.worst_tree += " colours " + std::to_string(colours);
        }
      }
      return;
    }
    for (int p = 0; p < vertex; ++p) {
      parent[vertex] = p;
      grow(vertex + 1);
    }
  };
  grow(1);
  return check;
}

struct NamedTableau {
  const char* name;
  const PartitionedTableau* tableau;
  bool gauss;  // â = a; otherwise Lobatto IIIA (a) – IIIB (â)
};

const std::vector<NamedTableau>& tableaux() {
  static const std::vector<NamedTableau> all = {
      {"gauss1", &coefficients::kGauss1, true},      {"gauss2", &coefficients::kGauss2, true},
      {"gauss3", &coefficients::kGauss3, true},      {"lobatto2", &coefficients::kLobatto2, false},
      {"lobatto3", &coefficients::kLobatto3, false}, {"lobatto4", &coefficients::kLobatto4, false},
  };
  return all;
}

// Every bicoloured tree up to the declared order ((n−1)! recursive trees × 2ⁿ colourings at order
// n: 7,680 at order 6) satisfies Φ = 1/γ, and some tree of order p + 1 does not, so the declared
// order is the order.
TEST(RungeKuttaTables, TreeOrderConditionsHoldExactlyUpToTheDeclaredOrder) {
  for (const auto& [name, tableau, gauss] : tableaux()) {
    SCOPED_TRACE(name);
    for (int order = 1; order <= tableau->order; ++order) {
      const TreeCheck check = check_trees(*tableau, order);
      EXPECT_LE(check.worst, kTolerance) << "order " << order << ", " << check.worst_tree;
    }
    EXPECT_GT(check_trees(*tableau, tableau->order + 1).worst, kViolated)
        << "satisfies the conditions of order " << tableau->order + 1;
  }
}

// Simplifying assumptions (Butcher 1964; Hairer & Wanner, Solving ODEs II, §IV.5):
//   B(p): Σ_i b_i c_i^{k−1} = 1/k,                    k ≤ p,
//   C(η): Σ_j a_ij c_j^{k−1} = c_i^k / k,             k ≤ η,
//   D(ζ): Σ_i b_i c_i^{k−1} a_ij = b_j(1 − c_j^k)/k,  k ≤ ζ.
// Gauss: B(2s), C(s), D(s). Lobatto IIIA: B(2s−2), C(s), D(s−2); IIIB: C(s−2), D(s).
Real defect_b(const PartitionedTableau& t, int p) {
  Real worst = 0;
  for (int k = 1; k <= p; ++k) {
    Real sum = 0;
    for (int i = 0; i < t.stages; ++i) sum += t.b[i] * std::pow(t.c[i], k - 1);
    worst = std::max(worst, std::fabs(sum - 1.0L / k));
  }
  return worst;
}

Real defect_c(const PartitionedTableau& t, const std::array<std::array<Real, 4>, 4>& a, int eta) {
  Real worst = 0;
  for (int k = 1; k <= eta; ++k) {
    for (int i = 0; i < t.stages; ++i) {
      Real sum = 0;
      for (int j = 0; j < t.stages; ++j) sum += a[i][j] * std::pow(t.c[j], k - 1);
      worst = std::max(worst, std::fabs(sum - std::pow(t.c[i], k) / k));
    }
  }
  return worst;
}

Real defect_d(const PartitionedTableau& t, const std::array<std::array<Real, 4>, 4>& a, int zeta) {
  Real worst = 0;
  for (int k = 1; k <= zeta; ++k) {
    for (int j = 0; j < t.stages; ++j) {
      Real sum = 0;
      for (int i = 0; i < t.stages; ++i) sum += t.b[i] * std::pow(t.c[i], k - 1) * a[i][j];
      worst = std::max(worst, std::fabs(sum - t.b[j] * (1 - std::pow(t.c[j], k)) / k));
    }
  }
  return worst;
}

TEST(RungeKuttaTables, SimplifyingAssumptions) {
  for (const auto& [name, tableau, gauss] : tableaux()) {
    SCOPED_TRACE(name);
    const int s = tableau->stages;
    EXPECT_LE(defect_b(*tableau, tableau->order), kTolerance);
    EXPECT_GT(defect_b(*tableau, tableau->order + 1), kViolated);  // quadrature order is sharp
    if (gauss) {
      EXPECT_LE(defect_c(*tableau, tableau->a, s), kTolerance);
      EXPECT_LE(defect_d(*tableau, tableau->a, s), kTolerance);
    } else {
      EXPECT_LE(defect_c(*tableau, tableau->a, s), kTolerance);          // IIIA: C(s)
      EXPECT_LE(defect_d(*tableau, tableau->a, s - 2), kTolerance);      // IIIA: D(s−2)
      EXPECT_LE(defect_c(*tableau, tableau->a_hat, s - 2), kTolerance);  // IIIB: C(s−2)
      EXPECT_LE(defect_d(*tableau, tableau->a_hat, s), kTolerance);      // IIIB: D(s)
    }
  }
}

// Symplecticity (GNI §VI.4): b_i â_ij + b_j a_ji − b_i b_j = 0 for all i, j
// (â = a for Gauss: b_i a_ij + b_j a_ji − b_i b_j = 0), with b̂ = b. Symmetry (GNI §V.2): a_{s+1−i,
// s+1−j} + a_ij = b_j for both tables, and c_i = Σ_j a_ij = Σ_j â_ij (â: for s ≥ 3).
TEST(RungeKuttaTables, SymplecticSymmetricAndConsistent) {
  for (const auto& [name, tableau, gauss] : tableaux()) {
    SCOPED_TRACE(name);
    const int s = tableau->stages;
    const auto& a = tableau->a;
    const auto& a_hat = tableau->a_hat;
    const auto& b = tableau->b;
    for (int i = 0; i < s; ++i) {
      Real row = 0, row_hat = 0;
      for (int j = 0; j < s; ++j) {
        EXPECT_LE(std::fabs(b[i] * a_hat[i][j] + b[j] * a[j][i] - b[i] * b[j]), kTolerance)
            << i << "," << j;
        EXPECT_LE(std::fabs(a[s - 1 - i][s - 1 - j] + a[i][j] - b[j]), kTolerance);
        EXPECT_LE(std::fabs(a_hat[s - 1 - i][s - 1 - j] + a_hat[i][j] - b[j]), kTolerance);
        row += a[i][j];
        row_hat += a_hat[i][j];
      }
      EXPECT_LE(std::fabs(row - tableau->c[i]), kTolerance);
      // Lobatto IIIB has C(s − 2) only: for s = 2 its rows sum to ½, not to c_i.
      if (gauss || s >= 3) {
        EXPECT_LE(std::fabs(row_hat - tableau->c[i]), kTolerance);
      }
    }
  }
}

// Negative control: the trees see a wrong digit. Lobatto IIIA with itself (no IIIB) is order 4
// for s = 3 but not symplectic; perturbing one Gauss entry breaks order 6.
TEST(RungeKuttaTables, NegativeControls) {
  PartitionedTableau perturbed = coefficients::kGauss3;
  perturbed.a[1][0] += 1e-12L;
  perturbed.a_hat[1][0] += 1e-12L;
  EXPECT_GT(check_trees(perturbed, 6).worst, 1e-14L);
  PartitionedTableau iiia_only = coefficients::kLobatto3;
  iiia_only.a_hat = iiia_only.a;
  EXPECT_LE(check_trees(iiia_only, 4).worst, kTolerance);  // Lobatto IIIA alone: order 4
  const Real b0 = iiia_only.b[0], a00 = iiia_only.a[0][0];
  EXPECT_GT(std::fabs(2 * b0 * a00 - b0 * b0), kViolated);  // … but not symplectic
}

// ---------------------------------------------------------------------------------------------
// Symmetric compositions of a symmetric second-order method Φ_h (GNI §V.3.2). Its modified flow
// has only odd powers of h: Φ_h = exp(hA + h³B + h⁵C + h⁷D + O(h⁹)) with A the vector field
// (GNI §V.2 and §IX.1). The composition Ψ_h = Φ_{γ_s h} ∘ … ∘ Φ_{γ_1 h} has order p for every
// such base iff exp(γ_s X) ⋯ exp(γ_1 X) agrees with exp(a) in the free associative algebra on
// letters a, b, c, d of degrees 1, 3, 5, 7 (X_γ = γa + γ³b + γ⁵c + γ⁷d) in every word of degree
// ≤ p: the letters stand for arbitrary operators, so no cancellation among them can be relied
// on. This is the BCH route to the order conditions of GNI §V.3.2 and contains all of them
// (orders 2, 4, 6, 8: 1, 1, 2, 4 conditions); the degree-(p+1) words show the order is sharp.

using Word = std::vector<int>;  // letters 0..3 = a, b, c, d
using Series = std::map<Word, Real>;

int degree(const Word& word) {
  int d = 0;
  for (int letter : word) d += 2 * letter + 1;
  return d;
}

Series multiply(const Series& x, const Series& y, int max_degree) {
  Series out;
  for (const auto& [u, cu] : x) {
    for (const auto& [v, cv] : y) {
      if (degree(u) + degree(v) > max_degree) continue;
      Word w = u;
      w.insert(w.end(), v.begin(), v.end());
      out[w] += cu * cv;
    }
  }
  return out;
}

// exp(x) truncated at max_degree; x has no constant term.
Series exponential(const Series& x, int max_degree) {
  Series result{{Word{}, 1.0L}};
  Series power{{Word{}, 1.0L}};
  for (int k = 1; k <= max_degree; ++k) {
    power = multiply(power, x, max_degree);
    for (auto& [w, c] : power) c /= k;  // power = x^k / k!
    for (const auto& [w, c] : power) result[w] += c;
  }
  return result;
}

// max |coefficient(Ψ) − coefficient(exp(a))| over the words of degree exactly `d`.
std::map<int, Real> composition_defects(std::span<const long double> gamma, int max_degree) {
  Series psi{{Word{}, 1.0L}};
  for (const long double g : gamma) {
    const Series x{
        {Word{0}, g}, {Word{1}, g * g * g}, {Word{2}, std::pow(g, 5)}, {Word{3}, std::pow(g, 7)}};
    psi = multiply(exponential(x, max_degree), psi, max_degree);  // Φ_{γ_i h} after the others
  }
  Series exact = exponential(Series{{Word{0}, 1.0L}}, max_degree);
  std::map<int, Real> defects;
  for (int d = 1; d <= max_degree; ++d) defects[d] = 0;
  for (const auto& [w, c] : psi) {
    if (w.empty()) continue;
    const auto it = exact.find(w);
    const Real target = it == exact.end() ? 0.0L : it->second;
    defects[degree(w)] = std::max(defects[degree(w)], std::fabs(c - target));
  }
  return defects;
}

TEST(CompositionSchemes, PalindromicAndConsistent) {
  for (const auto& scheme : coefficients::kCompositionSchemes) {
    SCOPED_TRACE(std::string(scheme.name));
    const auto& g = scheme.gamma;
    Real sum = 0;
    for (size_t i = 0; i < g.size(); ++i) {
      EXPECT_EQ(g[i], g[g.size() - 1 - i]) << i;  // γ_i = γ_{s+1−i}, bit for bit
      sum += g[i];
    }
    EXPECT_LE(std::fabs(sum - 1), kTolerance);
  }
}

// The classical conditions written out (GNI §V.3.2): Σγ_i^{2k+1} = 0 for 3 ≤ 2k+1 < p, and for
// order ≥ 6 the second order-6 condition Σ_i γ_i³(Σ_{j<i}γ_j + γ_i/2)² = 0. (The remaining
// order-8 conditions are covered by the BCH test below.)
TEST(CompositionSchemes, PowerSumConditions) {
  for (const auto& scheme : coefficients::kCompositionSchemes) {
    SCOPED_TRACE(std::string(scheme.name));
    for (int power = 3; power < scheme.order; power += 2) {
      Real sum = 0;
      for (const long double g : scheme.gamma) sum += std::pow(g, power);
      EXPECT_LE(std::fabs(sum), kTolerance) << "sum gamma^" << power;
    }
    Real sum = 0;
    for (const long double g : scheme.gamma) sum += std::pow(g, scheme.order + 1);
    EXPECT_GT(std::fabs(sum), kViolated) << "sum gamma^" << scheme.order + 1;
    Real nested = 0, before = 0;
    for (const long double g : scheme.gamma) {
      nested += g * g * g * (before + g / 2) * (before + g / 2);
      before += g;
    }
    if (scheme.order >= 6) {
      EXPECT_LE(std::fabs(nested), kTolerance);
    } else {
      EXPECT_GT(std::fabs(nested), kViolated);
    }
  }
}

TEST(CompositionSchemes, BchOrderConditionsHoldUpToTheDeclaredOrder) {
  for (const auto& scheme : coefficients::kCompositionSchemes) {
    SCOPED_TRACE(std::string(scheme.name));
    const auto defects = composition_defects(scheme.gamma, scheme.order + 1);
    for (int d = 1; d <= scheme.order; ++d) {
      EXPECT_LE(defects.at(d), kTolerance) << "degree " << d;
    }
    EXPECT_GT(defects.at(scheme.order + 1), kViolated) << "order is not sharp";
  }
}

TEST(CompositionSchemes, NegativeControlAWrongDigitIsSeen) {
  std::array<long double, 17> gamma{};
  std::copy(coefficients::kKahanLi8.begin(), coefficients::kKahanLi8.end(), gamma.begin());
  gamma[1] += 1e-12L;  // γ_2 = γ_16 only: Σγ and Σγ³ move by 2e-12 and 1.9e-12
  gamma[15] += 1e-12L;
  const auto defects = composition_defects(gamma, 8);
  EXPECT_GT(defects.at(1), 1e-13L);
  EXPECT_GT(defects.at(3), 1e-13L);
}

}  // namespace
}  // namespace high_order_coefficients_test
}  // namespace geomint
