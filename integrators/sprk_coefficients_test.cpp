// Order conditions of every SPRK table (sprk_coefficients.hpp) in long double: the splitting's
// product exp(â₁hB) exp(a₁hA) ⋯ against exp(h(A + B)) in the free associative algebra (BCH, GNI
// §III.5), and for the Nyström-only tables the bicoloured trees of q'' = f(q) (GNI §III.2).
#include "integrators/sprk_coefficients.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace geomint {
namespace sprk_coefficients_test {
namespace {

using Real = long double;
using coefficients::SprkTable;
// A condition that fails by more than this is violated, not merely rounded (rounding leaves
// < 1e-15; Sofroniou & Spaletta's order-10 table was optimised so that its order-11 defect is
// only 1.8e-9).
constexpr Real kViolated = 1e-10L;

// ---------------------------------------------------------------------------------------------
// General separable H. A (drift) and B (kick) stand for arbitrary non-commuting operators: a word
// of n letters is an n-bit integer (bit 1 = B), and a series holds one coefficient per word of
// length ≤ max. The step is Π_i exp(â_i B) exp(a_i A) (h absorbed into the degree); it has order p
// for every separable H iff it agrees with exp(A + B) in every word of length ≤ p.
using Series = std::vector<std::vector<Real>>;  // [length][word]

Series identity_series(int max) {
  Series s(max + 1);
  for (int n = 0; n <= max; ++n) s[n].assign(size_t{1} << n, 0.0L);
  s[0][0] = 1;
  return s;
}

// x · exp(c L) with L = A (letter 0) or B (letter 1).
Series times_exponential(const Series& x, Real c, int letter, int max) {
  Series out = identity_series(max);
  out[0][0] = 0;
  for (int n = 0; n <= max; ++n) {
    for (size_t u = 0; u < x[n].size(); ++u) {
      if (x[n][u] == 0) continue;
      Real term = x[n][u];
      size_t word = u;
      for (int k = 0; n + k <= max; ++k) {
        out[n + k][word] += term;
        term *= c / (k + 1);
        word = (word << 1) | static_cast<size_t>(letter);
      }
    }
  }
  return out;
}

// The largest |coefficient| difference from exp(A + B) (the sum over all words of length n is
// 1/n! for each word) among the words of length `length`.
Real splitting_defect(const SprkTable& table, int length) {
  Series product = identity_series(length);
  for (size_t i = 0; i < table.a.size(); ++i) {
    if (table.a_hat[i] != 0) product = times_exponential(product, table.a_hat[i], 1, length);
    if (table.a[i] != 0) product = times_exponential(product, table.a[i], 0, length);
  }
  Real exact = 1;
  for (int k = 2; k <= length; ++k) exact /= k;
  Real worst = 0;
  for (Real coefficient : product[length]) {
    worst = std::max(worst, std::fabs(coefficient - exact));
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// q' = M⁻¹p, p' = f(q) (T quadratic): bicoloured trees whose colours alternate, a q-vertex
// (g(p) = M⁻¹p, linear) having at most one child. As a partitioned RK method the table is
// Q_i = q₀ + h Σ_{j<i} a_j g(P_j) (the kick of stage i sees the drifts before it) and
// P_i = p₀ + h Σ_{j≤i} â_j f(Q_j), with weights a (q) and â (p); Φ(t) = 1/γ(t) (GNI §III.2.1).
Real nystrom_defect(const SprkTable& table, int order) {
  const int s = static_cast<int>(table.a.size());
  Real worst = 0;
  std::vector<int> parent(order, -1);
  const std::function<void(int)> grow = [&](int vertex) {
    if (vertex < order) {
      for (int p = 0; p < vertex; ++p) {
        parent[vertex] = p;
        grow(vertex + 1);
      }
      return;
    }
    std::vector<int> size(order, 1), depth(order, 0), children(order, 0);
    for (int v = 1; v < order; ++v) {
      depth[v] = depth[parent[v]] + 1;
      ++children[parent[v]];
    }
    for (int v = order - 1; v >= 1; --v) size[parent[v]] += size[v];
    Real gamma = 1;
    for (int v = 0; v < order; ++v) gamma *= size[v];
    for (int root_colour = 0; root_colour < 2; ++root_colour) {
      // colour 0: q-vertex (g, reached through a), 1: p-vertex (f, through â).
      bool nystrom = true;
      for (int v = 0; v < order; ++v) {
        if ((depth[v] + root_colour) % 2 == 0 && children[v] > 1) nystrom = false;
      }
      if (!nystrom) continue;
      std::vector<std::vector<Real>> w(order, std::vector<Real>(s, 1.0L));
      for (int v = order - 1; v >= 1; --v) {
        const bool p_vertex = (depth[v] + root_colour) % 2 == 1;
        for (int i = 0; i < s; ++i) {
          Real sum = 0;
          if (p_vertex) {
            for (int j = 0; j <= i; ++j) sum += table.a_hat[j] * w[v][j];
          } else {
            for (int j = 0; j < i; ++j) sum += table.a[j] * w[v][j];
          }
          w[parent[v]][i] *= sum;
        }
      }
      Real phi = 0;
      for (int i = 0; i < s; ++i) phi += (root_colour ? table.a_hat[i] : table.a[i]) * w[0][i];
      worst = std::max(worst, std::fabs(phi - 1 / gamma));
    }
  };
  grow(1);
  return worst;
}

Real defect(const SprkTable& table, int order) {
  return table.nystrom_only ? nystrom_defect(table, order) : splitting_defect(table, order);
}

// Every condition up to the declared order holds to the published precision of the coefficients
// (a few ulps of long double for exact or 40-digit tables), and some condition of order p + 1
// fails: the declared order is the order.
TEST(SprkTables, OrderConditionsHoldUpToTheDeclaredOrderAndNoFurther) {
  for (const SprkTable& table : coefficients::kSprkTables) {
    SCOPED_TRACE(std::string(table.name));
    const Real tolerance = std::max(table.published_precision * 10, 1e-17L);
    for (int order = 1; order <= table.order; ++order) {
      EXPECT_LE(defect(table, order), tolerance) << "order " << order;
    }
    EXPECT_GT(defect(table, table.order + 1), kViolated) << "order " << table.order + 1;
  }
}

// The Nyström-only tables are exactly that: they fail a general-splitting condition of their
// order (so the kind is not mislabelled), and the general tables also satisfy the (weaker)
// Nyström conditions, which checks the tree code against the BCH code.
TEST(SprkTables, NystromOnlyTablesNeedAQuadraticKineticEnergy) {
  for (const SprkTable& table : coefficients::kSprkTables) {
    SCOPED_TRACE(std::string(table.name));
    if (table.nystrom_only) {
      EXPECT_GT(splitting_defect(table, table.order), kViolated);
    } else if (table.order <= 6) {
      EXPECT_LE(nystrom_defect(table, table.order),
                std::max(table.published_precision * 10, 1e-17L));
    }
  }
}

// Symmetric ⇔ the sequence of (kick, drift) weights, zeros dropped and neighbours of one kind
// merged, is a palindrome (the adjoint step runs it backwards, GNI §V.1).
TEST(SprkTables, SymmetryFlagMatchesThePalindrome) {
  for (const SprkTable& table : coefficients::kSprkTables) {
    SCOPED_TRACE(std::string(table.name));
    std::vector<std::pair<int, Real>> sequence;
    auto push = [&](int kind, Real weight) {
      if (weight == 0) return;
      if (!sequence.empty() && sequence.back().first == kind) {
        sequence.back().second += weight;
      } else {
        sequence.emplace_back(kind, weight);
      }
    };
    for (size_t i = 0; i < table.a.size(); ++i) {
      push(1, table.a_hat[i]);
      push(0, table.a[i]);
    }
    bool palindrome = true;
    for (size_t i = 0; i < sequence.size(); ++i) {
      const auto& mirror = sequence[sequence.size() - 1 - i];
      palindrome = palindrome && mirror.first == sequence[i].first &&
                   std::fabs(mirror.second - sequence[i].second) <= 1e-15L;
    }
    EXPECT_EQ(palindrome, table.symmetric);
  }
}

// Negative control: one wrong digit in a weight breaks the conditions, in both checks.
TEST(SprkTables, AWrongDigitIsSeen) {
  std::array<long double, 4> a = coefficients::kSprkMcLachlan4A;
  a[1] += 1e-12L;
  SprkTable perturbed = coefficients::kSprkTables[7];
  ASSERT_EQ(perturbed.name, "mclachlan4");
  perturbed.a = a;
  EXPECT_GT(splitting_defect(perturbed, 4), 1e-14L);
  std::array<long double, 7> b = coefficients::kSprkBlanesMoan4AHat;
  b[2] += 1e-12L;
  SprkTable perturbed_bm = coefficients::kSprkTables[12];
  ASSERT_EQ(perturbed_bm.name, "blanes_moan4");
  perturbed_bm.a_hat = b;
  EXPECT_GT(nystrom_defect(perturbed_bm, 4), 1e-14L);
}

}  // namespace
}  // namespace sprk_coefficients_test
}  // namespace geomint
