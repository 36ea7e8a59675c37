// Explicit Runge–Kutta–Nyström tables for q'' = f(q) (Hairer, Nørsett & Wanner I, §II.14):
// Nyström's classical order-4 method and the FSAL pairs of Dormand, El-Mikkawy & Prince (IMA J.
// Numer. Anal. 7, 1987: RKN4(3)4FM, RKN5(4)6FM, RKN6(4)6FM, pp. 235–250; RKN8(6)9FM, pp. 423–430).
// Exact rationals.
#pragma once

#include <string_view>
#include <vector>

namespace geomint::coefficients {

// One step from (q, v): Q_i = q + c_i h v + h² Σ_j abar_ij f(Q_j),
// q⁺ = q + h v + h² Σ bbar_i f(Q_i), v⁺ = v + h Σ b_i f(Q_i); the embedded solution (if any) uses
// bbar_hat and b_hat. `abar` is lower triangular, row i holding j < i.
struct RknTable {
  std::string_view name;
  int order = 0;
  int embedded_order = 0;  // 0: no embedded solution (fixed-step only)
  std::string_view source;
  std::vector<long double> c;
  std::vector<std::vector<long double>> abar;
  std::vector<long double> bbar, b;
  std::vector<long double> bbar_hat, b_hat;  // empty without an embedded solution
  // First same as last: the last stage sits at c = 1 with abar_s = bbar, so f(Q_s) = f(q⁺) starts
  // the next step and a step costs one gradient less.
  bool fsal() const {
    if (c.back() != 1.0L || abar.back().size() + 1 != bbar.size()) return false;
    for (size_t j = 0; j < abar.back().size(); ++j) {
      if (abar.back()[j] != bbar[j]) return false;
    }
    return bbar.back() == 0.0L;
  }
};

namespace rkn_detail {
constexpr long double q(long long numerator, long long denominator) {
  return static_cast<long double>(numerator) / static_cast<long double>(denominator);
}
}  // namespace rkn_detail

inline const std::vector<RknTable>& rkn_tables() {
  using rkn_detail::q;
  static const std::vector<RknTable> tables = {
      {"nystrom4",
       4,
       0,
       "Nyström 1925, 3 stages (Hairer, Nørsett & Wanner I, §II.14)",
       {0, q(1, 2), 1},
       {{}, {q(1, 8)}, {0, q(1, 2)}},
       {q(1, 6), q(1, 3), 0},
       {q(1, 6), q(2, 3), q(1, 6)},
       {},
       {}},
      {"dprkn4",
       4,
       3,
       "Dormand, El-Mikkawy & Prince 1987, RKN4(3)4FM",
       {0, q(1, 4), q(7, 10), 1},
       {{}, {q(1, 32)}, {q(7, 1000), q(119, 500)}, {q(1, 14), q(8, 27), q(25, 189)}},
       {q(1, 14), q(8, 27), q(25, 189), 0},
       {q(1, 14), q(32, 81), q(250, 567), q(5, 54)},
       {q(-7, 150), q(67, 150), q(3, 20), q(-1, 20)},
       {q(13, 21), q(-20, 27), q(275, 189), q(-1, 3)}},
      {"dprkn5",
       5,
       4,
       "Dormand, El-Mikkawy & Prince 1987, RKN5(4)6FM",
       {0, q(1, 8), q(1, 4), q(1, 2), q(3, 4), 1},
       {{},
        {q(1, 128)},
        {q(1, 96), q(1, 48)},
        {q(1, 24), 0, q(1, 12)},
        {q(9, 128), 0, q(9, 64), q(9, 128)},
        {q(7, 90), 0, q(4, 15), q(1, 15), q(4, 45)}},
       {q(7, 90), 0, q(4, 15), q(1, 15), q(4, 45), 0},
       {q(7, 90), 0, q(16, 45), q(2, 15), q(16, 45), q(7, 90)},
       {q(1, 6), 0, 0, q(1, 3), 0, 0},
       {0, 0, q(2, 3), q(-1, 3), q(2, 3), 0}},
      {"dprkn6",
       6,
       4,
       "Dormand, El-Mikkawy & Prince 1987, RKN6(4)6FM",
       {0, q(1, 10), q(3, 10), q(7, 10), q(17, 25), 1},
       {{},
        {q(1, 200)},
        {q(-1, 2200), q(1, 22)},
        {q(637, 6600), q(-7, 110), q(7, 33)},
        {q(225437, 1968750), q(-30073, 281250), q(65569, 281250), q(-9367, 984375)},
        {q(151, 2142), q(5, 116), q(385, 1368), q(55, 168), q(-6250, 28101)}},
       {q(151, 2142), q(5, 116), q(385, 1368), q(55, 168), q(-6250, 28101), 0},
       {q(151, 2142), q(25, 522), q(275, 684), q(275, 252), q(-78125, 112404), q(1, 12)},
       {q(1349, 157500), q(7873, 50000), q(192199, 900000), q(521683, 2100000), q(-16, 125), 0},
       {q(1349, 157500), q(7873, 45000), q(27457, 90000), q(521683, 630000), q(-2, 5), q(1, 12)}},
      {"dprkn8",
       8,
       6,
       "Dormand, El-Mikkawy & Prince 1987, RKN8(6)9FM",
       {0, q(1, 20), q(1, 10), q(3, 10), q(1, 2), q(7, 10), q(9, 10), 1, 1},
       {{},
        {q(1, 800)},
        {q(1, 600), q(1, 300)},
        {q(9, 200), q(-9, 100), q(9, 100)},
        {q(-66701, 197352), q(28325, 32892), q(-2665, 5482), q(2170, 24669)},
        {q(227015747, 304251000), q(-54897451, 30425100), q(12942349, 10141700), q(-9499, 304251),
         q(539, 9250)},
        {q(-1131891597, 901789000), q(41964921, 12882700), q(-6663147, 3220675), q(270954, 644135),
         q(-108, 5875), q(114, 1645)},
        {q(13836959, 3667458), q(-17731450, 1833729), q(1063919505, 156478208),
         q(-33213845, 39119552), q(13335, 28544), q(-705, 14272), q(1645, 57088)},
        {q(223, 7938), 0, q(1175, 8064), q(925, 6048), q(41, 448), q(925, 14112), q(1175, 72576),
         0}},
       {q(223, 7938), 0, q(1175, 8064), q(925, 6048), q(41, 448), q(925, 14112), q(1175, 72576), 0,
        0},
       {q(223, 7938), 0, q(5875, 36288), q(4625, 21168), q(41, 224), q(4625, 21168), q(5875, 36288),
        q(223, 7938), 0},
       {q(7987313, 109941300), 0, q(1610737, 44674560), q(10023263, 33505920), q(-497221, 12409600),
        q(10023263, 78180480), q(1610737, 402071040), 0, 0},
       {q(7987313, 109941300), 0, q(1610737, 40207104), q(10023263, 23454144), q(-497221, 6204800),
        q(10023263, 23454144), q(1610737, 40207104), q(-4251941, 54970650), q(3, 20)}},
  };
  return tables;
}

}  // namespace geomint::coefficients
