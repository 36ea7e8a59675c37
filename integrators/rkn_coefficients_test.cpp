// Order conditions of every RKN table (rkn_coefficients.hpp) in long double: the bicoloured trees
// of q'' = f(q) whose q-vertices have at most one child (Hairer, Nørsett & Wanner I, §II.14), for
// the main solution at its declared order and for the embedded one at its own.
#include "integrators/rkn_coefficients.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace geomint {
namespace rkn_coefficients_test {
namespace {

using Real = long double;
using coefficients::RknTable;
// Exact rationals, each rounded once to long double: the conditions' sums leave < 1e-17.
constexpr Real kHolds = 1e-16L;
constexpr Real kViolated = 1e-8L;

struct Weights {
  const std::vector<long double>& bbar;  // q root
  const std::vector<long double>& b;     // v root
};

// Largest |Φ(t) − 1/γ(t)| over the Nyström trees of exactly `order` vertices. A f-vertex at stage
// i multiplies its children's weights; a q-vertex child of stage i weighs c_i when it is a leaf,
// Σ_j abar_ij Φ_j(subtree) when it has its one f-child. The root is a q-vertex (weights bbar;
// the one-vertex tree is q⁺ = q + hv, exact) or an f-vertex (weights b). γ is the usual density
// on the whole tree, q-vertices included (the RKN step written as a partitioned RK method).
Real nystrom_defect(const RknTable& table, const Weights& weights, int order) {
  const int s = static_cast<int>(table.c.size());
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
    for (int root_is_f = 0; root_is_f < 2; ++root_is_f) {
      const auto is_q = [&](int v) { return (depth[v] + root_is_f) % 2 == 0; };
      bool nystrom = true;
      for (int v = 0; v < order; ++v) {
        if (is_q(v) && children[v] > 1) nystrom = false;
      }
      if (!nystrom) continue;
      // w[v][i]: the weight of the subtree at v seen from stage i (f-vertex: evaluated at stage
      // i; q-vertex: as a child of stage i).
      std::vector<std::vector<Real>> w(order, std::vector<Real>(s, 1.0L));
      for (int v = order - 1; v >= 0; --v) {
        if (is_q(v) && v != 0) {
          if (children[v] == 0) {
            for (int i = 0; i < s; ++i) w[v][i] = table.c[i];
          } else {
            int child = -1;
            for (int u = v + 1; u < order; ++u) {
              if (parent[u] == v) child = u;
            }
            std::vector<Real> sum(s, 0.0L);
            for (int i = 0; i < s; ++i) {
              for (size_t j = 0; j < table.abar[i].size(); ++j) {
                sum[i] += table.abar[i][j] * w[child][j];
              }
            }
            w[v] = sum;
          }
        }
        if (v != 0) {
          // Multiply into the parent only from an f-parent's point of view (q-parents took
          // their child's weight above).
          if (!is_q(parent[v])) {
            for (int i = 0; i < s; ++i) w[parent[v]][i] *= w[v][i];
          }
        }
      }
      Real phi = 0;
      if (root_is_f) {
        for (int i = 0; i < s; ++i) phi += weights.b[i] * w[0][i];
      } else if (order == 1) {
        phi = 1;
      } else {
        int child = 1;  // the root's one f-child
        for (int i = 0; i < s; ++i) phi += weights.bbar[i] * w[child][i];
      }
      worst = std::max(worst, std::fabs(phi - 1 / gamma));
    }
  };
  grow(1);
  return worst;
}

Real main_defect(const RknTable& table, int order) {
  return nystrom_defect(table, {table.bbar, table.b}, order);
}
Real embedded_defect(const RknTable& table, int order) {
  return nystrom_defect(table, {table.bbar_hat, table.b_hat}, order);
}

TEST(RknTables, ShapesAreConsistent) {
  for (const RknTable& table : coefficients::rkn_tables()) {
    SCOPED_TRACE(std::string(table.name));
    const size_t s = table.c.size();
    ASSERT_EQ(table.abar.size(), s);
    for (size_t i = 0; i < s; ++i) ASSERT_EQ(table.abar[i].size(), i);
    ASSERT_EQ(table.bbar.size(), s);
    ASSERT_EQ(table.b.size(), s);
    if (table.embedded_order > 0) {
      ASSERT_EQ(table.bbar_hat.size(), s);
      ASSERT_EQ(table.b_hat.size(), s);
      EXPECT_TRUE(table.fsal());  // every Dormand–El-Mikkawy–Prince pair here is FSAL
    }
    // Row sums of abar are c²/2 (the stage's q is exact for constant f): a layout check.
    for (size_t i = 0; i < s; ++i) {
      Real sum = 0;
      for (Real a : table.abar[i]) sum += a;
      EXPECT_NEAR(static_cast<double>(sum), static_cast<double>(table.c[i] * table.c[i] / 2), 1e-15)
          << "row " << i;
    }
  }
}

// Every condition up to the declared order holds to the rounding of exact rationals, and some
// condition of order p + 1 fails: the declared order is the order. The same for the embedded
// solution at its own order (the error estimate's order sets the controller's exponent).
TEST(RknTables, OrderConditionsHoldUpToTheDeclaredOrderAndNoFurther) {
  for (const RknTable& table : coefficients::rkn_tables()) {
    SCOPED_TRACE(std::string(table.name));
    for (int order = 1; order <= table.order; ++order) {
      EXPECT_LE(main_defect(table, order), kHolds) << "order " << order;
    }
    EXPECT_GT(main_defect(table, table.order + 1), kViolated) << "order " << table.order + 1;
    if (table.embedded_order == 0) continue;
    for (int order = 1; order <= table.embedded_order; ++order) {
      EXPECT_LE(embedded_defect(table, order), kHolds) << "embedded order " << order;
    }
    EXPECT_GT(embedded_defect(table, table.embedded_order + 1), kViolated)
        << "embedded order " << table.embedded_order + 1;
  }
}

// Negative control: one wrong digit (1e-12) in one coefficient breaks a condition, in abar, bbar
// and b.
TEST(RknTables, AWrongDigitIsSeen) {
  for (const RknTable& original : coefficients::rkn_tables()) {
    if (original.name != "dprkn8") continue;
    RknTable perturbed = original;
    perturbed.abar[5][2] += 1e-12L;
    EXPECT_GT(main_defect(perturbed, 8), 1e-14L);
    perturbed = original;
    perturbed.bbar[3] += 1e-12L;
    EXPECT_GT(main_defect(perturbed, 2), 1e-14L);
    perturbed = original;
    perturbed.b_hat[7] += 1e-12L;
    EXPECT_GT(embedded_defect(perturbed, 1), 1e-14L);
    return;
  }
  FAIL() << "dprkn8 missing";
}

}  // namespace
}  // namespace rkn_coefficients_test
}  // namespace geomint
