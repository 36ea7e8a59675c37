// The IVP Test Set's ROBER (Mazzia & Magherini, release 2.4, problem rober.f; Robertson 1966;
// Hairer & Wanner, Solving ODEs II, §IV.1): the stiff chemical kinetics
// y1' = −0.04 y1 + 10⁴ y2 y3, y2' = 0.04 y1 − 10⁴ y2 y3 − 3·10⁷ y2², y3' = 3·10⁷ y2²,
// y(0) = (1, 0, 0), t ∈ [0, 10¹¹], with the Test Set's reference at t = 10¹¹.
#include "problems/first_order.hpp"

namespace geomint {
namespace {

constexpr double kK1 = 0.04, kK2 = 3e7, kK3 = 1e4;

class Robertson final : public FirstOrderProblem {
 public:
  Robertson() : FirstOrderProblem((Vec(3) << 1.0, 0.0, 0.0).finished(), kEndReference) {
    set_defaults(1e-3, 1e11);
    // rober.f, subroutine solut (RADAU5 in extended precision).
    set_end_reference(
        1e11, (Vec(3) << 0.2083340149701255e-07, 0.8333360770334713e-13, 0.9999999791665050e+00)
                  .finished());
  }

  void rhs(double, const Vec& y, Vec& ydot) const override {
    ydot.resize(3);
    ydot[0] = -kK1 * y[0] + kK3 * y[1] * y[2];
    ydot[1] = kK1 * y[0] - kK3 * y[1] * y[2] - kK2 * y[1] * y[1];
    ydot[2] = kK2 * y[1] * y[1];
  }

  void rhs_jacobian(double, const Vec& y, SparseMatrix& J) const override {
    const double d0[3] = {-kK1, kK3 * y[2], kK3 * y[1]};
    const double d2[3] = {0.0, 2 * kK2 * y[1], 0.0};
    J.resize(3, 3);
    J.setZero();
    J.reserve(9);
    for (int col = 0; col < 3; ++col) {
      J.insert(0, col) = d0[col];
      J.insert(1, col) = -d0[col] - d2[col];
      J.insert(2, col) = d2[col];
    }
    J.makeCompressed();
  }
};

}  // namespace

std::unique_ptr<Problem> make_robertson(Params&) { return std::make_unique<Robertson>(); }

}  // namespace geomint
