// Coefficients of the high-order methods, as named long-double constants with their sources:
// symmetric composition schemes (Hairer, Lubich & Wanner, GNI §V.3.2), Gauss–Legendre and
// Lobatto IIIA/IIIB tableaux (GNI §II.1.3, §II.2.2; Hairer & Wanner, Solving ODEs II, §IV.5).
// integrators/high_order_coefficients_test.cpp checks every table's order conditions in long
// double.
#pragma once

#include <array>
#include <span>
#include <string_view>

namespace geomint::coefficients {

// sqrt(3), sqrt(5), sqrt(15) to 37 digits (std::sqrt is not constexpr).
inline constexpr long double kSqrt3 = 1.732050807568877293527446341505872367L;
inline constexpr long double kSqrt5 = 2.236067977499789696409173668731276235L;
inline constexpr long double kSqrt15 = 3.872983346207416885179265399782399611L;

// ---------------------------------------------------------------------------------------------
// Symmetric compositions Ψ_h = Φ_{γ_s h} ∘ … ∘ Φ_{γ_1 h} of a symmetric second-order method Φ
// (GNI §V.3.2); every scheme is palindromic, γ_i = γ_{s+1−i}, and Σγ_i = 1.

// Yoshida (1990), "Construction of higher order symplectic integrators", Phys. Lett. A 150:
// the triple jump, γ_1 = γ_3 = 1/(2 − 2^{1/3}), γ_2 = −2^{1/3}/(2 − 2^{1/3}); order 4, s = 3.
inline constexpr long double kYoshida4Outer = 1.351207191959657634047687808971460827L;
inline constexpr long double kYoshida4Middle = -1.702414383919315268095375617942921654L;
inline constexpr std::array<long double, 3> kYoshida4 = {kYoshida4Outer, kYoshida4Middle,
                                                         kYoshida4Outer};

// Suzuki (1990), "Fractal decomposition of exponential operators", Phys. Lett. A 146:
// γ_1 = γ_2 = γ_4 = γ_5 = 1/(4 − 4^{1/3}), γ_3 = −4^{1/3}/(4 − 4^{1/3}); order 4, s = 5.
inline constexpr long double kSuzuki4Outer = 0.4144907717943757371423540628607614957L;
inline constexpr long double kSuzuki4Middle = -0.6579630871775029485694162514430459828L;
inline constexpr std::array<long double, 5> kSuzuki4 = {
    kSuzuki4Outer, kSuzuki4Outer, kSuzuki4Middle, kSuzuki4Outer, kSuzuki4Outer};

// Kahan & Li (1997), "Composition constants for raising the orders of unconventional schemes for
// ordinary differential equations", Math. Comp. 66, method s9odr6a: order 6, s = 9 (also in
// GNI §V.3.2).
inline constexpr std::array<long double, 9> kKahanLi6 = {
    0.39216144400731413927925056L,  0.33259913678935943859974864L, -0.70624617255763935980996482L,
    0.08221359629355080023149045L,  0.79854399093482996339895035L, 0.08221359629355080023149045L,
    -0.70624617255763935980996482L, 0.33259913678935943859974864L, 0.39216144400731413927925056L,
};

// Yoshida (1990), solution A: the 7-stage order-6 scheme (w₃ w₂ w₁ w₀ w₁ w₂ w₃). Yoshida prints 15
// digits; these are the root of Σγ = 1, Σγ³ = Σγ⁵ = 0 and the nested order-6 condition (the
// conditions PowerSumConditions checks) found by Newton in 60-digit decimal arithmetic from his
// digits, which they reproduce.
inline constexpr long double kYoshida6W1 = -1.177679984178871006946415680964315735L;
inline constexpr long double kYoshida6W2 = 0.2355732133593581336847931829785346017L;
inline constexpr long double kYoshida6W3 = 0.7845136104775572638194976338663498758L;
inline constexpr long double kYoshida6W0 = 1.315186320683911218884249728238862514L;
inline constexpr std::array<long double, 7> kYoshida6 = {
    kYoshida6W3, kYoshida6W2, kYoshida6W1, kYoshida6W0, kYoshida6W1, kYoshida6W2, kYoshida6W3};

// Kahan & Li (1997), method s17odr8a: order 8, s = 17 (also in GNI §V.3.2).
inline constexpr std::array<long double, 17> kKahanLi8 = {
    0.13020248308889008087881763L,  0.56116298177510838456196441L,  -0.38947496264484728640807860L,
    0.15884190655515560089621075L,  -0.39590389413323757733623154L, 0.18453964097831570709183254L,
    0.25837438768632204729397911L,  0.29501172360931029887096624L,  -0.60550853383003451169892108L,
    0.29501172360931029887096624L,  0.25837438768632204729397911L,  0.18453964097831570709183254L,
    -0.39590389413323757733623154L, 0.15884190655515560089621075L,  -0.38947496264484728640807860L,
    0.56116298177510838456196441L,  0.13020248308889008087881763L,
};

// McLachlan (1995), "On the numerical integration of ordinary differential equations by symmetric
// composition methods", SIAM J. Sci. Comput. 16: order 8, s = 15.
inline constexpr std::array<long double, 15> kMcLachlan8 = {
    0.74167036435061295344822780L,  -0.40910082580003159399730010L, 0.19075471029623837995387626L,
    -0.57386247111608226665638773L, 0.29906418130365592384446354L,  0.33462491824529818378495798L,
    0.31529309239676659663205666L,  -0.79688793935291635401978884L, 0.31529309239676659663205666L,
    0.33462491824529818378495798L,  0.29906418130365592384446354L,  -0.57386247111608226665638773L,
    0.19075471029623837995387626L,  -0.40910082580003159399730010L, 0.74167036435061295344822780L,
};

struct CompositionScheme {
  std::string_view name;  // spec value of composition:scheme=
  int order;
  std::span<const long double> gamma;
  std::string_view source;
};

inline constexpr std::array<CompositionScheme, 6> kCompositionSchemes = {{
    {"yoshida4", 4, kYoshida4, "Yoshida 1990, s=3"},
    {"suzuki4", 4, kSuzuki4, "Suzuki 1990, s=5"},
    {"yoshida6", 6, kYoshida6, "Yoshida 1990 solution A, s=7"},
    {"kahan_li6", 6, kKahanLi6, "Kahan & Li 1997, s=9"},
    {"kahan_li8", 8, kKahanLi8, "Kahan & Li 1997, s=17"},
    {"mclachlan8", 8, kMcLachlan8, "McLachlan 1995, s=15"},
}};

// ---------------------------------------------------------------------------------------------
// Partitioned Runge–Kutta tableaux (a, â, b, c) for q' = M⁻¹p (coefficients a) and
// p' = f(q, M⁻¹p, t) (coefficients â): Q_i = q₀ + hΣa_ij M⁻¹P_j, P_i = p₀ + hΣâ_ij f(Q_j, …).
// Stored as 4×4 arrays; only the leading s×s block is used.
struct PartitionedTableau {
  int stages;
  int order;
  std::array<std::array<long double, 4>, 4> a;      // positions
  std::array<std::array<long double, 4>, 4> a_hat;  // momenta
  std::array<long double, 4> b;                     // both components
  std::array<long double, 4> c;
  std::string_view source;
};

// Gauss–Legendre collocation, order 2s (GNI §II.1.3 and §VI.4; Butcher 1964). The same
// tableau for both components (â = a).
inline constexpr PartitionedTableau kGauss1 = {
    1, 2, {{{0.5L}}}, {{{0.5L}}}, {1.0L}, {0.5L}, "Gauss-Legendre s=1 (implicit midpoint)"};

inline constexpr std::array<std::array<long double, 4>, 4> kGauss2A = {{
    {0.25L, 0.25L - kSqrt3 / 6},
    {0.25L + kSqrt3 / 6, 0.25L},
}};
inline constexpr PartitionedTableau kGauss2 = {2,
                                               4,
                                               kGauss2A,
                                               kGauss2A,
                                               {0.5L, 0.5L},
                                               {0.5L - kSqrt3 / 6, 0.5L + kSqrt3 / 6},
                                               "Gauss-Legendre s=2"};

inline constexpr std::array<std::array<long double, 4>, 4> kGauss3A = {{
    {5.0L / 36, 2.0L / 9 - kSqrt15 / 15, 5.0L / 36 - kSqrt15 / 30},
    {5.0L / 36 + kSqrt15 / 24, 2.0L / 9, 5.0L / 36 - kSqrt15 / 24},
    {5.0L / 36 + kSqrt15 / 30, 2.0L / 9 + kSqrt15 / 15, 5.0L / 36},
}};
inline constexpr PartitionedTableau kGauss3 = {3,
                                               6,
                                               kGauss3A,
                                               kGauss3A,
                                               {5.0L / 18, 4.0L / 9, 5.0L / 18},
                                               {0.5L - kSqrt15 / 10, 0.5L, 0.5L + kSqrt15 / 10},
                                               "Gauss-Legendre s=3"};

// Lobatto IIIA (a: collocation at the Lobatto points) with Lobatto IIIB (â), order 2s − 2 and
// symplectic for separable H (GNI §II.2.2 and §VI.4; Hairer & Wanner, Solving ODEs II, §IV.5;
// Jay 1996). s = 2 is Störmer–Verlet.
inline constexpr PartitionedTableau kLobatto2 = {2,
                                                 2,
                                                 {{{0.0L, 0.0L}, {0.5L, 0.5L}}},
                                                 {{{0.5L, 0.0L}, {0.5L, 0.0L}}},
                                                 {0.5L, 0.5L},
                                                 {0.0L, 1.0L},
                                                 "Lobatto IIIA-IIIB s=2 (Stormer-Verlet)"};

inline constexpr PartitionedTableau kLobatto3 = {
    3,
    4,
    {{{0.0L, 0.0L, 0.0L}, {5.0L / 24, 1.0L / 3, -1.0L / 24}, {1.0L / 6, 2.0L / 3, 1.0L / 6}}},
    {{{1.0L / 6, -1.0L / 6, 0.0L}, {1.0L / 6, 1.0L / 3, 0.0L}, {1.0L / 6, 5.0L / 6, 0.0L}}},
    {1.0L / 6, 2.0L / 3, 1.0L / 6},
    {0.0L, 0.5L, 1.0L},
    "Lobatto IIIA-IIIB s=3"};

inline constexpr PartitionedTableau kLobatto4 = {
    4,
    6,
    {{{0.0L, 0.0L, 0.0L, 0.0L},
      {(11 + kSqrt5) / 120, (25 - kSqrt5) / 120, (25 - 13 * kSqrt5) / 120, (-1 + kSqrt5) / 120},
      {(11 - kSqrt5) / 120, (25 + 13 * kSqrt5) / 120, (25 + kSqrt5) / 120, (-1 - kSqrt5) / 120},
      {1.0L / 12, 5.0L / 12, 5.0L / 12, 1.0L / 12}}},
    {{{1.0L / 12, (-1 - kSqrt5) / 24, (-1 + kSqrt5) / 24, 0.0L},
      {1.0L / 12, (25 + kSqrt5) / 120, (25 - 13 * kSqrt5) / 120, 0.0L},
      {1.0L / 12, (25 + 13 * kSqrt5) / 120, (25 - kSqrt5) / 120, 0.0L},
      {1.0L / 12, (11 - kSqrt5) / 24, (11 + kSqrt5) / 24, 0.0L}}},
    {1.0L / 12, 5.0L / 12, 5.0L / 12, 1.0L / 12},
    {0.0L, (5 - kSqrt5) / 10, (5 + kSqrt5) / 10, 1.0L},
    "Lobatto IIIA-IIIB s=4"};

}  // namespace geomint::coefficients
