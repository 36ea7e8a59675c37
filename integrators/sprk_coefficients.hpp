// Coefficient tables of explicit symplectic partitioned Runge–Kutta (splitting) methods for
// H = T(p) + V(q): the tables of SUNDIALS 7's SPRKStep, whose papers are cited per table, and
// Blanes & Moan (2002), J. Comput. Appl. Math. 142, Table 3. Audited in sprk_coefficients_test.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string_view>

#include "integrators/high_order_coefficients.hpp"

namespace geomint::coefficients {

// A step is s stages; stage i kicks, then drifts (the SPRKStep convention, ARKODE docs §2.5):
//   p ← p − h â_i ∇V(q),   q ← q + h a_i M⁻¹p.
// `nystrom_only`: the order holds when T is quadratic in p (q'' = f(q), Runge–Kutta–Nyström),
// not for every separable H; the audit checks the matching set of conditions.
struct SprkTable {
  std::string_view name;  // spec value of sprk:table=
  int order;
  std::span<const long double> a;      // drift weights
  std::span<const long double> a_hat;  // kick weights
  bool symmetric;                      // the step is its own adjoint (palindromic sequence)
  bool nystrom_only;
  long double published_precision;  // the coefficients' published rounding (audit tolerance)
  std::string_view source;
};

// A symmetric composition of kick–drift–kick Verlet steps with weights γ (GNI §V.3.2), written as
// one table: drift γ_i, kick (γ_{i−1} + γ_i)/2, the two half kicks at either end.
template <std::size_t N>
constexpr std::array<long double, N + 1> composition_drifts(const std::array<long double, N>& g) {
  std::array<long double, N + 1> a{};
  for (std::size_t i = 0; i < N; ++i) a[i] = g[i];
  return a;
}
template <std::size_t N>
constexpr std::array<long double, N + 1> composition_kicks(const std::array<long double, N>& g) {
  std::array<long double, N + 1> a_hat{};
  a_hat[0] = g[0] / 2;
  for (std::size_t i = 1; i < N; ++i) a_hat[i] = (g[i - 1] + g[i]) / 2;
  a_hat[N] = g[N - 1] / 2;
  return a_hat;
}

// Symplectic Euler (kick, then drift).
inline constexpr std::array<long double, 1> kSprkEulerA = {1.0L};
inline constexpr std::array<long double, 1> kSprkEulerAHat = {1.0L};

// Leapfrog (drift–kick–drift) and pseudo-leapfrog (kick–drift–kick); Candy & Rozmus (1991),
// J. Comput. Phys. 92.
inline constexpr std::array<long double, 2> kSprkLeapfrogA = {0.5L, 0.5L};
inline constexpr std::array<long double, 2> kSprkLeapfrogAHat = {0.0L, 1.0L};
inline constexpr std::array<long double, 2> kSprkPseudoLeapfrogA = {1.0L, 0.0L};
inline constexpr std::array<long double, 2> kSprkPseudoLeapfrogAHat = {0.5L, 0.5L};

// Ruth (1983), IEEE Trans. Nucl. Sci. 30: order 3, rational weights.
inline constexpr std::array<long double, 3> kSprkRuth3A = {2.0L / 3, -2.0L / 3, 1.0L};
inline constexpr std::array<long double, 3> kSprkRuth3AHat = {7.0L / 24, 3.0L / 4, -1.0L / 24};

// McLachlan & Atela (1992), Nonlinearity 5: the optimal order-2 (a₂ = 1 − √2/2) and order-3
// (root of a cubic, evaluated in 40-digit arithmetic) two- and three-stage methods.
inline constexpr long double kHalfSqrt2 = 0.7071067811865475244008443621048490392848L;
inline constexpr std::array<long double, 2> kSprkMcLachlan2A = {kHalfSqrt2, 1 - kHalfSqrt2};
inline constexpr std::array<long double, 2> kSprkMcLachlan2AHat = {1 - kHalfSqrt2, kHalfSqrt2};
inline constexpr std::array<long double, 3> kSprkMcLachlan3A = {
    0.9196615230173998570508976381533827895633L, -0.1879916187991597820078528680788819290445L,
    0.2683300957817599249569552299254991394812L};
inline constexpr std::array<long double, 3> kSprkMcLachlan3AHat = {
    kSprkMcLachlan3A[2], kSprkMcLachlan3A[1], kSprkMcLachlan3A[0]};

// Candy & Rozmus (1991) = Forest & Ruth (1990): Yoshida's triple jump as drift–kick–drift,
// a₁ = (2 + 2^{1/3} + 2^{−1/3})/6, a₂ = (1 − 2^{1/3} − 2^{−1/3})/6, â₂ = 1/(2 − 2^{1/3}).
inline constexpr std::array<long double, 4> kSprkCandyRozmus4A = {
    0.675603595979828817023843904485730413461L, -0.175603595979828817023843904485730413461L,
    -0.175603595979828817023843904485730413461L, 0.675603595979828817023843904485730413461L};
inline constexpr std::array<long double, 4> kSprkCandyRozmus4AHat = {
    0.0L, kYoshida4Outer, kYoshida4Middle, kYoshida4Outer};

// McLachlan & Atela (1992), the order-4 four-stage and order-5 six-stage methods (18-19 digits
// as printed).
inline constexpr std::array<long double, 4> kSprkMcLachlan4A = {
    0.515352837431122936L, -0.085782019412973646L, 0.441583023616466524L, 0.128846158365384185L};
inline constexpr std::array<long double, 4> kSprkMcLachlan4AHat = {
    0.134496199277431089L, -0.224819803079420806L, 0.756320000515668291L, 0.33400360328632142L};
inline constexpr std::array<long double, 6> kSprkMcLachlan5A = {
    0.339839625839110000L,  -0.088601336903027329L, 0.5858564768259621188L,
    -0.603039356536491888L, 0.3235807965546976394L, 0.4423637942197494587L};
inline constexpr std::array<long double, 6> kSprkMcLachlan5AHat = {
    0.1193900292875672758L, 0.6989273703824752308L, -0.1713123582716007754L,
    0.4012695022513534480L, 0.0107050818482359840L, -0.0589796254980311632L};

// Yoshida (1990) solution A (order 6, 7 Verlet steps) and Suzuki & Umeno (1993) / McLachlan (1995)
// (order 8, 15 Verlet steps), the compositions of high_order_coefficients.hpp as tables.
inline constexpr auto kSprkYoshida6A = composition_drifts(kYoshida6);
inline constexpr auto kSprkYoshida6AHat = composition_kicks(kYoshida6);
inline constexpr auto kSprkSuzukiUmeno8A = composition_drifts(kMcLachlan8);
inline constexpr auto kSprkSuzukiUmeno8AHat = composition_kicks(kMcLachlan8);

// Sofroniou & Spaletta (2005), Optim. Methods Softw. 20: order 10, 35 Verlet steps, palindromic
// (γ₁ … γ₁₈ … γ₁), 32 digits as printed.
inline constexpr std::array<long double, 18> kSofroniou10Half = {
    0.078795722521686419263907679337684L,   0.31309610341510852776481247192647L,
    0.027918383235078066109520273275299L,   -0.22959284159390709415121339679655L,
    0.13096206107716486317465685927961L,    -0.26973340565451071434460973222411L,
    0.074973343155891435666137105641410L,   0.11199342399981020488957508073640L,
    0.36613344954622675119314812353150L,    -0.39910563013603589787862981058340L,
    0.10308739852747107731580277001372L,    0.41143087395589023782070411897608L,
    -0.0048663605831352617621956593099771L, -0.39203335370863990644808193642610L,
    0.051942502962449647037182904015976L,   0.050665090759924496335874344156866L,
    0.049674370639729879054568800279461L,   0.049317735759594537917680008339338L};
constexpr std::array<long double, 35> palindrome35(const std::array<long double, 18>& half) {
  std::array<long double, 35> full{};
  for (std::size_t i = 0; i < 18; ++i) full[i] = full[34 - i] = half[i];
  return full;
}
inline constexpr auto kSofroniou10 = palindrome35(kSofroniou10Half);
inline constexpr auto kSprkSofroniou10A = composition_drifts(kSofroniou10);
inline constexpr auto kSprkSofroniou10AHat = composition_kicks(kSofroniou10);

// Blanes & Moan (2002), Table 3: SRKN_6^b (order 4) and SRKN_11^b (order 6), kick first and last
// (B A B … A B), 15 digits as printed, the middle weights from Σa = Σb = 1.
inline constexpr long double kBm4B1 = 0.0829844064174052L, kBm4B2 = 0.396309801498368L,
                             kBm4B3 = -0.0390563049223486L, kBm4A1 = 0.245298957184271L,
                             kBm4A2 = 0.604872665711080L;
inline constexpr long double kBm4A3 = 0.5L - (kBm4A1 + kBm4A2);
inline constexpr long double kBm4B4 = 1.0L - 2 * (kBm4B1 + kBm4B2 + kBm4B3);
inline constexpr std::array<long double, 7> kSprkBlanesMoan4A = {kBm4A1, kBm4A2, kBm4A3, kBm4A3,
                                                                 kBm4A2, kBm4A1, 0.0L};
inline constexpr std::array<long double, 7> kSprkBlanesMoan4AHat = {kBm4B1, kBm4B2, kBm4B3, kBm4B4,
                                                                    kBm4B3, kBm4B2, kBm4B1};

inline constexpr std::array<long double, 6> kBm6B = {0.0414649985182624L,  0.198128671918067L,
                                                     -0.0400061921041533L, 0.0752539843015807L,
                                                     -0.0115113874206879L, 0.2366699247869311L};
inline constexpr std::array<long double, 5> kBm6A = {0.123229775946271L, 0.290553797799558L,
                                                     -0.127049212625417L, -0.246331761062075L,
                                                     0.357208872795928L};
constexpr std::array<long double, 12> blanes_moan6_drifts() {
  std::array<long double, 12> a{};
  long double middle = 1.0L;
  for (std::size_t i = 0; i < 5; ++i) {
    a[i] = a[10 - i] = kBm6A[i];
    middle -= 2 * kBm6A[i];
  }
  a[5] = middle;
  a[11] = 0.0L;
  return a;
}
constexpr std::array<long double, 12> blanes_moan6_kicks() {
  std::array<long double, 12> a_hat{};
  for (std::size_t i = 0; i < 6; ++i) a_hat[i] = a_hat[11 - i] = kBm6B[i];
  return a_hat;
}
inline constexpr auto kSprkBlanesMoan6A = blanes_moan6_drifts();
inline constexpr auto kSprkBlanesMoan6AHat = blanes_moan6_kicks();

inline constexpr long double kExact = 1e-18L;  // exact rationals, or evaluated to 40 digits
inline constexpr std::array<SprkTable, 14> kSprkTables = {{
    {"euler1", 1, kSprkEulerA, kSprkEulerAHat, false, false, kExact, "symplectic Euler"},
    {"leapfrog2", 2, kSprkLeapfrogA, kSprkLeapfrogAHat, true, false, kExact,
     "leapfrog, Candy & Rozmus 1991"},
    {"pseudo_leapfrog2", 2, kSprkPseudoLeapfrogA, kSprkPseudoLeapfrogAHat, true, false, kExact,
     "pseudo-leapfrog, Candy & Rozmus 1991"},
    {"ruth3", 3, kSprkRuth3A, kSprkRuth3AHat, false, false, kExact, "Ruth 1983"},
    {"mclachlan2", 2, kSprkMcLachlan2A, kSprkMcLachlan2AHat, false, false, kExact,
     "McLachlan & Atela 1992"},
    {"mclachlan3", 3, kSprkMcLachlan3A, kSprkMcLachlan3AHat, false, false, kExact,
     "McLachlan & Atela 1992"},
    {"candy_rozmus4", 4, kSprkCandyRozmus4A, kSprkCandyRozmus4AHat, true, false, kExact,
     "Candy & Rozmus 1991"},
    {"mclachlan4", 4, kSprkMcLachlan4A, kSprkMcLachlan4AHat, false, true, 1e-17L,
     "McLachlan & Atela 1992"},
    {"mclachlan5", 5, kSprkMcLachlan5A, kSprkMcLachlan5AHat, false, true, 1e-17L,
     "McLachlan & Atela 1992"},
    {"yoshida6", 6, kSprkYoshida6A, kSprkYoshida6AHat, true, false, kExact, "Yoshida 1990"},
    {"suzuki_umeno8", 8, kSprkSuzukiUmeno8A, kSprkSuzukiUmeno8AHat, true, false, kExact,
     "Suzuki & Umeno 1993, McLachlan 1995"},
    {"sofroniou10", 10, kSprkSofroniou10A, kSprkSofroniou10AHat, true, false, kExact,
     "Sofroniou & Spaletta 2005"},
    {"blanes_moan4", 4, kSprkBlanesMoan4A, kSprkBlanesMoan4AHat, true, false, 1e-15L,
     "Blanes & Moan 2002, SRKN_6^b"},
    {"blanes_moan6", 6, kSprkBlanesMoan6A, kSprkBlanesMoan6AHat, true, true, 1e-15L,
     "Blanes & Moan 2002, SRKN_11^b"},
}};

}  // namespace geomint::coefficients
