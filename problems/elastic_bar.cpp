// Nonlinear elastic bar (docs/METHOD.md §6, Kharevych et al. 2006 §5): linear tetrahedra, lumped
// masses, F = D_s D_m⁻¹, St Venant–Kirchhoff or neo-Hookean W with P(F) and dP/dF from Sifakis &
// Barbič, "FEM simulation of 3D deformable solids" (2012); strain-rate damping after Kharevych
// §5.2.
#include "problems/elastic_bar.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "problems/force.hpp"
#include "problems/parallel.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace {

using Mat3 = Eigen::Matrix3d;
using Mat34 = Eigen::Matrix<double, 3, 4>;
using Mat43 = Eigen::Matrix<double, 4, 3>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat9x12 = Eigen::Matrix<double, 9, 12>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Vec3 = Eigen::Vector3d;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

enum class Material { kStvk, kNeoHookean };
enum class Init { kRest, kTwist, kBend, kVelocity };
// left: the face x = 0 removed from the dofs; none: free; constraint: that face kept as dofs and
// pinned by q_i − X_i = 0 (PAPER.md §3, docs/METHOD.md §3); pin: only the corner node at the
// origin pinned that way, so the angular momentum about it stays a conserved quantity.
enum class Clamp { kLeft, kNone, kFaceConstraint, kPinConstraint };

struct BarConfig {
  int nx = 8, ny = 2, nz = 2;
  double length = 1, width = 0.2, height = 0.2;
  Material material = Material::kNeoHookean;
  double young = 1e5, poisson = 0.3, density = 1000;
  Clamp clamp = Clamp::kLeft;
  bool clamp_left() const { return clamp == Clamp::kLeft; }
  bool pinned_by_constraint() const {
    return clamp == Clamp::kFaceConstraint || clamp == Clamp::kPinConstraint;
  }
  // Whether the motion is held at the face x = 0 (removed or constrained).
  bool face_held() const { return clamp == Clamp::kLeft || clamp == Clamp::kFaceConstraint; }
  double gravity = 9.81;
  double damping = 0;  // ν
  Init init = Init::kRest;
  double twist = 0.5, bend = 0.05, spin = 1, shake = 0.5;
  bool proj_spd = false;
};

// One linear tetrahedron. With displacements U = X − X_rest (3×4, one column per node),
// F = I + U G, where G = [−1ᵀD_m⁻¹; D_m⁻¹] (row a is ∂F/∂x_a): the form of F = D_s D_m⁻¹ that is
// exactly I at rest, so the energy and force vanish there without cancellation.
struct Tet {
  Mat43 G;
  double volume;
  std::array<int, 4> dof;  // first entry of each node in q, −1 for a clamped node
  // Offset of the (a, b) block inside node b's columns of K, at 4b + a; a node of the Kuhn mesh
  // has at most 15 neighbours (itself included), so offsets stay below 45.
  std::array<std::int8_t, 16> slot;
};

// vec(F) is column-major, index i + 3j for F_ij; A(i + 3j, k + 3l) = ∂P_ij/∂F_kl.
inline int vi(int i, int j) { return i + 3 * j; }

// St Venant–Kirchhoff: E = ½(FᵀF − I), W = μ tr(E²) + (λ/2)(tr E)², P = F S with
// S = 2μE + λ tr(E) I. With H = F − I, E = ½(H + Hᵀ + HᵀH) avoids forming FᵀF − I.
struct Stvk {
  double mu, lambda;

  static Mat3 green(const Mat3& H) { return 0.5 * (H + H.transpose() + H.transpose() * H); }

  double energy(const Mat3& H) const { return energy_of_strain(green(H)); }
  bool stress(const Mat3& H, Mat3& P) const {
    stress_of_strain(H, green(H), P);
    return true;
  }
  // energy(H) and stress(H, P) with E formed once: the same bits as the two.
  bool energy_and_stress(const Mat3& H, double& W, Mat3& P) const {
    const Mat3 E = green(H);
    W = energy_of_strain(E);
    stress_of_strain(H, E, P);
    return true;
  }
  double energy_of_strain(const Mat3& E) const {
    const double trace = E.trace();
    return mu * E.squaredNorm() + 0.5 * lambda * trace * trace;
  }
  void stress_of_strain(const Mat3& H, const Mat3& E, Mat3& P) const {
    const Mat3 S = 2 * mu * E + lambda * E.trace() * Mat3::Identity();
    P = (Mat3::Identity() + H) * S;
  }
  // dP = dF S + F dS, dS = μ(dFᵀF + FᵀdF) + λ tr(FᵀdF) I, hence
  // A(ij, kl) = δ_ik S_lj + μ F_il F_kj + μ (FFᵀ)_ik δ_lj + λ F_ij F_kl.
  bool stress_derivative(const Mat3& H, Mat9& A) const {
    const Mat3 F = Mat3::Identity() + H;
    const Mat3 E = green(H);
    const Mat3 S = 2 * mu * E + lambda * E.trace() * Mat3::Identity();
    gauss_newton_part(F, mu, lambda, A);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        for (int l = 0; l < 3; ++l) A(vi(i, j), vi(i, l)) += S(l, j);
      }
    }
    return true;
  }
  // The part of dP/dF that stems from dE alone: μ F_il F_kj + μ (FFᵀ)_ik δ_lj + λ F_ij F_kl. It is
  // also the Hessian of the damping potential in Ḟ (below), so it is shared.
  static void gauss_newton_part(const Mat3& F, double mu, double lambda, Mat9& A) {
    const Mat3 FFt = F * F.transpose();
    for (int l = 0; l < 3; ++l) {
      for (int k = 0; k < 3; ++k) {
        for (int j = 0; j < 3; ++j) {
          for (int i = 0; i < 3; ++i) {
            double value = mu * F(i, l) * F(k, j) + lambda * F(i, j) * F(k, l);
            if (l == j) value += mu * FFt(i, k);
            A(vi(i, j), vi(k, l)) = value;
          }
        }
      }
    }
  }
};

// Neo-Hookean: W = (μ/2)(tr FᵀF − 3) − μ ln J + (λ/2)(ln J)², P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ. W → +∞
// as J → 0⁺ and is undefined for J ≤ 0 (an inverted element); the methods return false there.
struct NeoHookean {
  double mu, lambda;

  // J − 1 = tr H + ½((tr H)² − tr(H²)) + det H (the invariants of I + H), so ln J = log1p(J − 1)
  // keeps full relative accuracy for small strains, as the Green strain does for StVK.
  static double log_det(const Mat3& H, bool& ok) {
    const double trace = H.trace();
    const double second = 0.5 * (trace * trace - (H * H).trace());
    const double j_minus_1 = trace + second + H.determinant();
    ok = j_minus_1 > -1;
    return ok ? std::log1p(j_minus_1) : kNaN;
  }

  double energy(const Mat3& H) const {
    bool ok = false;
    const double log_j = log_det(H, ok);
    return ok ? energy_of(H, log_j) : kInf;
  }
  bool stress(const Mat3& H, Mat3& P) const {
    bool ok = false;
    const double log_j = log_det(H, ok);
    if (ok) stress_of(H, log_j, P);
    return ok;
  }
  // energy(H) and stress(H, P) with ln J computed once: the same bits as the two (W = +∞ and
  // false for an inverted element).
  bool energy_and_stress(const Mat3& H, double& W, Mat3& P) const {
    bool ok = false;
    const double log_j = log_det(H, ok);
    W = ok ? energy_of(H, log_j) : kInf;
    if (ok) stress_of(H, log_j, P);
    return ok;
  }
  // tr FᵀF − 3 = 2 tr H + ‖H‖²
  double energy_of(const Mat3& H, double log_j) const {
    return 0.5 * mu * (2 * H.trace() + H.squaredNorm()) - mu * log_j + 0.5 * lambda * log_j * log_j;
  }
  void stress_of(const Mat3& H, double log_j, Mat3& P) const {
    const Mat3 F = Mat3::Identity() + H;
    const Mat3 Q = F.inverse().transpose();  // F⁻ᵀ
    P = mu * (F - Q) + lambda * log_j * Q;
  }
  // With Q = F⁻ᵀ, dQ = −Q dFᵀ Q and d ln J = Q : dF:
  // A(ij, kl) = μ δ_ik δ_jl + (μ − λ ln J) Q_il Q_kj + λ Q_ij Q_kl.
  bool stress_derivative(const Mat3& H, Mat9& A) const {
    bool ok = false;
    const double log_j = log_det(H, ok);
    if (!ok) return false;
    const Mat3 Q = (Mat3::Identity() + H).inverse().transpose();
    const double c = mu - lambda * log_j;
    for (int l = 0; l < 3; ++l) {
      for (int k = 0; k < 3; ++k) {
        for (int j = 0; j < 3; ++j) {
          for (int i = 0; i < 3; ++i) {
            A(vi(i, j), vi(k, l)) = c * Q(i, l) * Q(k, j) + lambda * Q(i, j) * Q(k, l);
          }
        }
      }
    }
    for (int m = 0; m < 9; ++m) A(m, m) += mu;
    return true;
  }
};

// K_e = vol Bᵀ A B with B = ∂vec(F)/∂x_e, B(i + 3j, 3a + k) = δ_ik G(a, j): two small products
// instead of a dense 9×12 B. Symmetrised so that the assembled matrix is symmetric to the bit.
void element_matrix(const Mat9& A, const Mat43& G, double volume, Mat12& K) {
  Mat9x12 AB;
  for (int b = 0; b < 4; ++b) {
    for (int l = 0; l < 3; ++l) {
      AB.col(3 * b + l) = A.col(l) * G(b, 0) + A.col(l + 3) * G(b, 1) + A.col(l + 6) * G(b, 2);
    }
  }
  for (int a = 0; a < 4; ++a) {
    const double g0 = volume * G(a, 0), g1 = volume * G(a, 1), g2 = volume * G(a, 2);
    for (int k = 0; k < 3; ++k) {
      K.row(3 * a + k) = g0 * AB.row(k) + g1 * AB.row(k + 3) + g2 * AB.row(k + 6);
    }
  }
  const Mat12 sum = K + K.transpose();
  K = 0.5 * sum;
}

class ElasticBar final : public Problem, public HolonomicConstraints, public NonConservativeForce {
 public:
  explicit ElasticBar(const BarConfig& config)
      : config_(config),
        mu_(config.young / (2 * (1 + config.poisson))),
        lambda_(config.young * config.poisson / ((1 + config.poisson) * (1 - 2 * config.poisson))) {
    build_mesh();
    unsigned capabilities = kHessian | kOmegaMax;
    // Internal forces are sums over elements of functions of F, invariant under rigid motions;
    // only the clamp and gravity break the symmetry, and the factory forbids gravity unclamped.
    if (config_.clamp == Clamp::kNone) capabilities |= kLinearMomentum | kAngularMomentum;
    // A pin at the origin exerts no torque about it: Σ q_i × p_i is conserved without gravity.
    if (config_.clamp == Clamp::kPinConstraint && config_.gravity == 0) {
      capabilities |= kAngularMomentum;
    }
    set_capabilities(capabilities);
    set_defaults(1e-3, 1.0);
    build_initial_state();
  }

  State initial_state() const override { return initial_; }

  // The element energies are computed in chunks, then summed in element order on one thread:
  // the same sum to the bit at any thread count.
  double potential(const Vec& q) const override {
    std::vector<double> element_energy(tets_.size());
    const int chunks = chunk_count(tets_.size(), kMinElementsPerChunk);
    for_each_chunk(chunks, tets_.size(), [&](int, std::size_t begin, std::size_t end) {
      for (std::size_t e = begin; e < end; ++e) {
        const Tet& tet = tets_[e];
        element_energy[e] = tet.volume * energy_density(displacement_gradient(tet, q));
      }
    });
    return total_potential(element_energy, q);
  }

  // g = Σ_e vol P G ᵀ (the columns are the forces on the 4 nodes) + the gravity load m_i g e_z.
  void gradient(const Vec& q, Vec& g) const override {
    assemble_nodal(
        [this, &q](const Tet& tet, Mat34& nodal) {
          Mat3 P;
          if (stress(displacement_gradient(tet, q), P)) {
            nodal = tet.volume * P * tet.G.transpose();
          } else {
            nodal.setConstant(kNaN);  // inverted neo-Hookean element: the harness reports "nan"
          }
        },
        g);
    add_gravity_load(g);
  }

  // potential(q) and gradient(q, g) in one element loop (H, and ln J or E, formed once per
  // element), with the bits of the two: the HP minimiser's line search needs E_k wherever it takes
  // the residual (docs/PERF.md "Energy with the gradient").
  bool potential_with_gradient(const Vec& q, Vec& g, double& V) const override {
    std::vector<double> element_energy(tets_.size());
    const Tet* first_tet = tets_.data();
    assemble_nodal(
        [&](const Tet& tet, Mat34& nodal) {
          Mat3 P;
          double w = 0;
          const bool finite = energy_and_stress(displacement_gradient(tet, q), w, P);
          element_energy[static_cast<std::size_t>(&tet - first_tet)] = tet.volume * w;
          if (finite) {
            nodal = tet.volume * P * tet.G.transpose();
          } else {
            nodal.setConstant(kNaN);
          }
        },
        g);
    add_gravity_load(g);
    V = total_potential(element_energy, q);
    return true;
  }

  void hessian(const Vec& q, SparseMatrix& H) const override {
    assemble(
        q,
        [this](const Tet& tet, const Mat3& Hd, Mat12& K) {
          Mat9 A;
          if (!stress_derivative(Hd, A)) {
            K.setConstant(kNaN);
            return;
          }
          element_matrix(A, tet.G, tet.volume, K);
          if (config_.proj_spd) project_to_psd(K);
        },
        H);
  }

  // Strain-rate damping: per element D = ν vol (μ tr(Ė²) + (λ/2)(tr Ė)²), Ė = ½(FᵀḞ + ḞᵀF),
  // Ḟ = V G. The force −∂D/∂v = −ν vol F S_d Gᵀ with S_d = 2μĖ + λ tr(Ė) I; Ė = 0 for any rigid
  // velocity field (Ḟ = ΩF, Ω skew), so momentum is untouched, and vᵀf = −2D ≤ 0.
  // Relation to the paper's D(q_k, q_{k+1}) = (ν/h) W_el(incremental deformation): the step's
  // deformation F_{k+1}F_k⁻¹ = I + h ḞF⁻¹ + O(h²) has Green strain h d + O(h²), d = F⁻ᵀĖF⁻¹, and
  // the quadratic part of W_el (the same μ, λ for both materials) turns (ν/h) W_el into
  // ν h vol (μ tr(d²) + (λ/2)(tr d)²), whose force −∂/∂q_{k+1} = −(1/h) ∂/∂v is this one with d
  // in place of Ė: equal at small strain, and both are C = νK at rest (docs/METHOD.md §6). Ė is
  // used because it keeps D an exact quadratic form in v (a constant, PSD C) at any F.
  const NonConservativeForce* as_forced() const override {
    return config_.damping > 0 ? this : nullptr;
  }
  bool has_force_jacobian() const override { return true; }
  void force(const Vec& q, const Vec& v, double, Vec& f) const override {
    const double nu = config_.damping;
    assemble_nodal(
        [this, &q, &v, nu](const Tet& tet, Mat34& nodal) {
          const Mat3 F = Mat3::Identity() + displacement_gradient(tet, q);
          const Mat3 Fdot = gather(tet, v, nullptr) * tet.G;
          const Mat3 FtFdot = F.transpose() * Fdot;
          const Mat3 Edot = 0.5 * (FtFdot + FtFdot.transpose());
          const Mat3 S = 2 * mu_ * Edot + lambda_ * Edot.trace() * Mat3::Identity();
          nodal = (-nu * tet.volume) * (F * S) * tet.G.transpose();
        },
        f);
  }

  // D is a quadratic form in Ḟ, so C = ∂²D/∂v² = vol Bᵀ A_d B is constant in v, symmetric PSD,
  // and f = −C v exactly. A_d is StVK's dP/dF without the geometric term δ_ik S_lj. The
  // q-dependence of f (through F) is not part of C.
  void force_jacobian_v(const Vec& q, const Vec&, double, SparseMatrix& C) const override {
    const double nu = config_.damping;
    assemble(
        q,
        [this, nu](const Tet& tet, const Mat3& Hd, Mat12& K) {
          Mat9 A;
          Stvk::gauss_newton_part(Mat3::Identity() + Hd, nu * mu_, nu * lambda_, A);
          element_matrix(A, tet.G, tet.volume, K);
        },
        C);
  }

  Vec linear_momentum(const Vec&, const Vec& p) const override {
    Vec3 total = Vec3::Zero();
    for (int i = 0; i < dof(); i += 3) total += p.segment<3>(i);
    return total;
  }
  // Σ x_i × p_i about the origin, over the (free) nodes.
  Vec angular_momentum(const Vec& q, const Vec& p) const override {
    Vec3 total = Vec3::Zero();
    for (int i = 0; i < dof(); i += 3) {
      total += Vec3(q.segment<3>(i)).cross(Vec3(p.segment<3>(i)));
    }
    return total;
  }

  // Pins q_i − X_i = 0, three rows per pinned node: G is a selection matrix, so the curvature
  // and the constraint Hessian vanish; the multipliers are the reaction forces on the pinned
  // nodes (with a minus sign: M q̈ = −∇V − Gᵀλ). Only clamp=constraint|pin has them.
  const HolonomicConstraints* as_constrained() const override {
    return config_.pinned_by_constraint() ? this : nullptr;
  }
  int constraint_count() const override { return 3 * static_cast<int>(pinned_dofs_.size()); }
  void constraint(const Vec& q, Vec& g) const override {
    g.resize(constraint_count());
    for (std::size_t k = 0; k < pinned_dofs_.size(); ++k) {
      const int d = pinned_dofs_[k];
      g.segment<3>(3 * static_cast<Eigen::Index>(k)) = q.segment<3>(d) - rest_q_.segment<3>(d);
    }
  }
  void constraint_jacobian(const Vec&, SparseMatrix& G) const override {
    G.resize(constraint_count(), dof());
    G.setZero();
    for (std::size_t k = 0; k < pinned_dofs_.size(); ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        G.insert(3 * static_cast<Eigen::Index>(k) + axis, pinned_dofs_[k] + axis) = 1;
      }
    }
    G.makeCompressed();
  }
  void constraint_curvature(const Vec&, const Vec&, Vec& c) const override {
    c = Vec::Zero(constraint_count());
  }
  void constraint_hessian(const Vec&, const Vec&, SparseMatrix& K) const override {
    K.resize(dof(), dof());
    K.setZero();
  }
  std::vector<std::string> multiplier_names() const override {
    std::vector<std::string> names;
    for (int node : pinned_nodes_) {
      for (const char* axis : {"x", "y", "z"})
        names.push_back(fmt::format("reaction{}_{}", node, axis));
    }
    return names;
  }

  // Element-by-element bound (Irons–Treharne): with the lumped M = Σ_e M_e, the Rayleigh quotient
  // xᵀKx / xᵀMx = Σ_e x_eᵀK_e x_e / Σ_e x_eᵀM_e x_e ≤ max_e λ_max(M_e⁻¹K_e), where M_e = (ρ vol/4)
  // I and clamped rows and columns are dropped from K_e. It bounds the frequencies of the exact
  // Hessian at q (the SPD projection only lowers eigenvalues). An element's Gershgorin bound
  // skips its eigen-solve when it cannot raise the maximum. +∞ if an element is inverted.
  double omega_max(const Vec& q) const override {
    double bound = 0;
    for (const Tet& tet : tets_) {
      Mat9 A;
      if (!stress_derivative(displacement_gradient(tet, q), A)) return kInf;
      Mat12 K;
      element_matrix(A, tet.G, tet.volume, K);
      for (int a = 0; a < 4; ++a) {
        if (tet.dof[a] < 0) {
          K.middleRows<3>(3 * a).setZero();
          K.middleCols<3>(3 * a).setZero();
        }
      }
      const double scale = 4 / (config_.density * tet.volume);
      if (scale * K.cwiseAbs().rowwise().sum().maxCoeff() <= bound) continue;
      Eigen::SelfAdjointEigenSolver<Mat12> solver(K, Eigen::EigenvaluesOnly);
      bound = std::max(bound, scale * solver.eigenvalues()[11]);
    }
    return std::sqrt(bound);
  }

  // tip_z: mean vertical displacement of the nodes on the free end face x = length.
  std::vector<std::string> series_names() const override { return {"tip_z"}; }
  void series_values(const Vec& q, const Vec&, std::vector<double>& values) const override {
    double sum = 0;
    for (int i : tip_dofs_) sum += q[i + 2] - rest_q_[i + 2];
    values.assign(1, sum / static_cast<double>(tip_dofs_.size()));
  }

  // Bytes held by the precomputed mesh data (for the benchmark's memory counter).
  std::size_t footprint_bytes() const {
    return tets_.capacity() * sizeof(Tet) +
           static_cast<std::size_t>(rest_q_.size() + initial_.q.size() + initial_.p.size() +
                                    2 * dof()) *
               sizeof(double) +
           (free_node_.capacity() + tip_dofs_.capacity() + first_element_.capacity()) *
               sizeof(int) +
           static_cast<std::size_t>(pattern_.nonZeros()) * (sizeof(double) + sizeof(int)) +
           static_cast<std::size_t>(pattern_.outerSize() + 1) * sizeof(int);
  }

 private:
  int node_index(int ix, int iy, int iz) const {
    return ix + (config_.nx + 1) * (iy + (config_.ny + 1) * iz);
  }

  // Node displacements of a tet as columns (zero for clamped nodes); `rest` subtracts X_rest.
  static Mat34 gather(const Tet& tet, const Vec& x, const Vec* rest) {
    Mat34 U;
    for (int a = 0; a < 4; ++a) {
      const int d = tet.dof[a];
      if (d < 0) {
        U.col(a).setZero();
      } else if (rest != nullptr) {
        U.col(a) = x.segment<3>(d) - rest->segment<3>(d);
      } else {
        U.col(a) = x.segment<3>(d);
      }
    }
    return U;
  }
  // H = F − I = U G.
  Mat3 displacement_gradient(const Tet& tet, const Vec& q) const {
    return gather(tet, q, &rest_q_) * tet.G;
  }

  double energy_density(const Mat3& H) const {
    return config_.material == Material::kStvk ? Stvk{mu_, lambda_}.energy(H)
                                               : NeoHookean{mu_, lambda_}.energy(H);
  }
  bool stress(const Mat3& H, Mat3& P) const {
    return config_.material == Material::kStvk ? Stvk{mu_, lambda_}.stress(H, P)
                                               : NeoHookean{mu_, lambda_}.stress(H, P);
  }
  bool energy_and_stress(const Mat3& H, double& W, Mat3& P) const {
    return config_.material == Material::kStvk
               ? Stvk{mu_, lambda_}.energy_and_stress(H, W, P)
               : NeoHookean{mu_, lambda_}.energy_and_stress(H, W, P);
  }
  bool stress_derivative(const Mat3& H, Mat9& A) const {
    return config_.material == Material::kStvk ? Stvk{mu_, lambda_}.stress_derivative(H, A)
                                               : NeoHookean{mu_, lambda_}.stress_derivative(H, A);
  }

  // Modified-Newton option: clamp the element's negative eigenvalues to zero. The result is no
  // longer the exact Hessian (only a PSD model of it), which is why it is off by default.
  static void project_to_psd(Mat12& K) {
    Eigen::SelfAdjointEigenSolver<Mat12> solver(K);
    if (solver.eigenvalues()[0] >= 0) return;
    const Eigen::Matrix<double, 12, 1> clamped = solver.eigenvalues().cwiseMax(0.0);
    const Mat12 projected =
        solver.eigenvectors() * clamped.asDiagonal() * solver.eigenvectors().transpose();
    K = 0.5 * (projected + projected.transpose());
  }

  double gravity_potential(const Vec& q) const {
    if (config_.gravity == 0) return 0;
    double sum = 0;
    for (int i = 2; i < dof(); i += 3) sum += mass()[i] * q[i];
    return config_.gravity * sum;
  }

  // Threads (problems/parallel.hpp): the element list is cut into contiguous chunks, and every
  // sum over elements is formed in element order whatever the chunk count, so results are the
  // same to the bit at any thread count. A chunk adds into an entry directly unless an earlier
  // chunk may touch it too, i.e. unless both of the entry's nodes occur in an earlier element
  // (first_element_); such contributions are queued in element order and added after all chunks
  // have finished, chunk by chunk. The earlier chunks' contributions to the entry are then all in,
  // and no two chunks ever write one entry at the same time. The queued entries are those of the
  // node layers shared by neighbouring chunks, a few per cent at 10⁴ elements.
  // Below this many elements per chunk a thread costs more than it saves (docs/PERF.md).
  static constexpr std::size_t kMinElementsPerChunk = 2048;
  // Below this many matrix entries per chunk a thread costs more than zeroing them saves.
  static constexpr std::size_t kMinEntriesPerChunk = std::size_t{1} << 16;

  // Whether chunk `chunk` starting at element `begin` must queue its additions to the node pair's
  // entries (or, with b = a, to node a's vector entries).
  bool shared_with_earlier_chunk(int chunk, std::size_t begin, int dof_a, int dof_b) const {
    return chunk > 0 && static_cast<std::size_t>(
                            std::max(first_element_[static_cast<std::size_t>(dof_a / 3)],
                                     first_element_[static_cast<std::size_t>(dof_b / 3)])) < begin;
  }

  // Σ_e of the element energies in element order, +∞ when one is not finite (an inverted
  // neo-Hookean element: outside the domain of V), plus the gravity potential.
  double total_potential(const std::vector<double>& element_energy, const Vec& q) const {
    double elastic = 0;
    for (const double energy : element_energy) {
      if (!(energy < kInf)) return kInf;
      elastic += energy;
    }
    return elastic + gravity_potential(q);
  }

  void add_gravity_load(Vec& g) const {
    if (config_.gravity != 0) {
      for (int i = 2; i < dof(); i += 3) g[i] += config_.gravity * mass()[i];
    }
  }

  // Σ_e of the 3×4 nodal vectors `element(tet, nodal)` into `out` (size dof(), zeroed first).
  template <class ElementFn>
  void assemble_nodal(const ElementFn& element, Vec& out) const {
    out.setZero(dof());
    const int chunks = chunk_count(tets_.size(), kMinElementsPerChunk);
    std::vector<std::vector<std::pair<int, double>>> queued(static_cast<std::size_t>(chunks));
    for_each_chunk(chunks, tets_.size(), [&](int chunk, std::size_t begin, std::size_t end) {
      auto& later = queued[static_cast<std::size_t>(chunk)];
      Mat34 nodal;
      for (std::size_t e = begin; e < end; ++e) {
        const Tet& tet = tets_[e];
        element(tet, nodal);
        for (int a = 0; a < 4; ++a) {
          const int d = tet.dof[a];
          if (d < 0) continue;
          if (shared_with_earlier_chunk(chunk, begin, d, d)) {
            for (int k = 0; k < 3; ++k) later.emplace_back(d + k, nodal(k, a));
          } else {
            out.segment<3>(d) += nodal.col(a);
          }
        }
      }
    });
    for (const auto& later : queued) {
      for (const auto& [index, value] : later) out[index] += value;
    }
  }

  // One pass over the elements, adding each K_e straight into the values of the fixed sparsity
  // pattern (built once with setFromTriplets, which merged the duplicate entries). Every node owns
  // 3 consecutive columns with identical row sets, so one offset per node pair locates the 3×3
  // block in all three. Scatter-adding beats re-sorting ~144 triplets per element on each call by
  // more than a factor of ten at 10⁵ elements. Entries (i, j) and (j, i) receive the same element
  // contributions in the same order, so the symmetry of K_e carries over to the last bit.
  template <class ElementFn>
  void assemble(const Vec& q, const ElementFn& element, SparseMatrix& out) const {
    reset_to_pattern(out);
    double* values = out.valuePtr();
    const int* outer = out.outerIndexPtr();
    const int chunks = chunk_count(tets_.size(), kMinElementsPerChunk);
    std::vector<std::vector<std::pair<std::ptrdiff_t, double>>> queued(
        static_cast<std::size_t>(chunks));
    for_each_chunk(chunks, tets_.size(), [&](int chunk, std::size_t begin, std::size_t end) {
      auto& later = queued[static_cast<std::size_t>(chunk)];
      Mat12 K;
      for (std::size_t e = begin; e < end; ++e) {
        const Tet& tet = tets_[e];
        element(tet, displacement_gradient(tet, q), K);
        for (int b = 0; b < 4; ++b) {
          if (tet.dof[b] < 0) continue;
          for (int a = 0; a < 4; ++a) {
            if (tet.dof[a] < 0) continue;
            const bool queue = shared_with_earlier_chunk(chunk, begin, tet.dof[a], tet.dof[b]);
            for (int l = 0; l < 3; ++l) {
              const std::ptrdiff_t block = outer[tet.dof[b] + l] + tet.slot[4 * b + a];
              for (int k = 0; k < 3; ++k) {
                if (queue) {
                  later.emplace_back(block + k, K(3 * a + k, 3 * b + l));
                } else {
                  values[block + k] += K(3 * a + k, 3 * b + l);
                }
              }
            }
          }
        }
      }
    });
    for (const auto& later : queued) {
      for (const auto& [index, value] : later) values[index] += value;
    }
  }

  // Makes `out` K's pattern with zero values. A matrix that already has the pattern (the caller's
  // from the last assembly) keeps its storage and only has its values zeroed, both on the threads
  // (half the memory traffic of copying pattern_, and no allocation); anything else gets a copy.
  void reset_to_pattern(SparseMatrix& out) const {
    const auto entries = static_cast<std::size_t>(pattern_.nonZeros());
    if (out.rows() != pattern_.rows() || out.cols() != pattern_.cols() || !out.isCompressed() ||
        static_cast<std::size_t>(out.nonZeros()) != entries ||
        !std::equal(pattern_.outerIndexPtr(), pattern_.outerIndexPtr() + pattern_.outerSize() + 1,
                    out.outerIndexPtr())) {
      out = pattern_;
      return;
    }
    const int chunks = chunk_count(entries, kMinEntriesPerChunk);
    std::vector<char> same(static_cast<std::size_t>(chunks), 0);
    const int* expected = pattern_.innerIndexPtr();
    const int* held = out.innerIndexPtr();
    double* values = out.valuePtr();
    for_each_chunk(chunks, entries, [&](int chunk, std::size_t begin, std::size_t end) {
      same[static_cast<std::size_t>(chunk)] =
          std::equal(expected + begin, expected + end, held + begin);
      std::fill(values + begin, values + end, 0.0);
    });
    if (std::find(same.begin(), same.end(), 0) != same.end()) out = pattern_;
  }

  // Sparsity pattern of K: 3×3 blocks for all node pairs that share an element, built from sorted
  // per-node neighbour lists (a triplet list would hold 144 entries per element, ~230 MB at 10⁵
  // elements), and per element the offset of row block a inside the columns of node b.
  void build_pattern() {
    const int nodes = dof() / 3;
    std::vector<std::vector<int>> neighbours(nodes);
    for (const Tet& tet : tets_) {
      for (int b = 0; b < 4; ++b) {
        if (tet.dof[b] < 0) continue;
        for (int a = 0; a < 4; ++a) {
          if (tet.dof[a] >= 0) neighbours[tet.dof[b] / 3].push_back(tet.dof[a] / 3);
        }
      }
    }
    std::size_t entries = 0;
    for (auto& list : neighbours) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      entries += 9 * list.size();
    }
    pattern_.resize(dof(), dof());
    pattern_.makeCompressed();
    pattern_.resizeNonZeros(static_cast<Eigen::Index>(entries));
    int* outer = pattern_.outerIndexPtr();
    int* inner = pattern_.innerIndexPtr();
    int position = 0;
    for (int node = 0; node < nodes; ++node) {
      for (int l = 0; l < 3; ++l) {
        outer[3 * node + l] = position;
        for (int neighbour : neighbours[node]) {
          for (int k = 0; k < 3; ++k) inner[position++] = 3 * neighbour + k;
        }
      }
    }
    outer[dof()] = position;
    std::fill_n(pattern_.valuePtr(), entries, 0.0);
    first_element_.assign(static_cast<std::size_t>(nodes), std::numeric_limits<int>::max());
    for (std::size_t e = tets_.size(); e-- > 0;) {
      for (int d : tets_[e].dof) {
        if (d >= 0) first_element_[static_cast<std::size_t>(d / 3)] = static_cast<int>(e);
      }
    }
    for (Tet& tet : tets_) {
      for (int b = 0; b < 4; ++b) {
        for (int a = 0; a < 4; ++a) {
          int offset = -1;
          if (tet.dof[a] >= 0 && tet.dof[b] >= 0) {
            const auto& list = neighbours[tet.dof[b] / 3];
            offset =
                3 * static_cast<int>(std::lower_bound(list.begin(), list.end(), tet.dof[a] / 3) -
                                     list.begin());
          }
          tet.slot[4 * b + a] = static_cast<std::int8_t>(offset);
        }
      }
    }
  }

  void build_mesh() {
    const int nx = config_.nx, ny = config_.ny, nz = config_.nz;
    const double hx = config_.length / nx, hy = config_.width / ny, hz = config_.height / nz;
    const int nodes = (nx + 1) * (ny + 1) * (nz + 1);

    // Free nodes in node order; the clamp removes the face x = 0.
    std::vector<int> node_dof(nodes, -1);
    for (int iz = 0; iz <= nz; ++iz) {
      for (int iy = 0; iy <= ny; ++iy) {
        for (int ix = config_.clamp_left() ? 1 : 0; ix <= nx; ++ix) {
          const int node = node_index(ix, iy, iz);
          node_dof[node] = 3 * static_cast<int>(free_node_.size());
          free_node_.push_back(node);
          if (ix == nx) tip_dofs_.push_back(node_dof[node]);
          const bool pinned = config_.clamp == Clamp::kFaceConstraint
                                  ? ix == 0
                                  : config_.clamp == Clamp::kPinConstraint && node == 0;
          if (pinned) {
            pinned_nodes_.push_back(node);
            pinned_dofs_.push_back(node_dof[node]);
          }
        }
      }
    }
    const int n = 3 * static_cast<int>(free_node_.size());
    rest_q_.resize(n);
    for (int f = 0; f < n / 3; ++f) {
      const int node = free_node_[f];
      const int ix = node % (nx + 1), iy = (node / (nx + 1)) % (ny + 1),
                iz = node / ((nx + 1) * (ny + 1));
      rest_q_.segment<3>(3 * f) = Vec3(ix * hx, iy * hy, iz * hz);
    }

    // Kuhn (Freudenthal) split: for each permutation (a, b, c) of the axes, the path
    // 0 → e_a → e_a + e_b → (1, 1, 1) through the cell. Every cell uses the same main diagonal,
    // so the faces of neighbouring cells are split identically: the mesh is conforming.
    static constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                                {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    const Vec3 spacing(hx, hy, hz);
    Vec lumped = Vec::Zero(n);
    tets_.reserve(static_cast<std::size_t>(6) * nx * ny * nz);
    for (int iz = 0; iz < nz; ++iz) {
      for (int iy = 0; iy < ny; ++iy) {
        for (int ix = 0; ix < nx; ++ix) {
          for (const auto& perm : kPermutations) {
            std::array<std::array<int, 3>, 4> corner{};
            for (int step = 1; step <= 3; ++step) {
              corner[step] = corner[step - 1];
              corner[step][perm[step - 1]] = 1;
            }
            Mat34 X;
            Tet tet;
            std::array<int, 4> node;
            for (int a = 0; a < 4; ++a) {
              node[a] = node_index(ix + corner[a][0], iy + corner[a][1], iz + corner[a][2]);
              for (int axis = 0; axis < 3; ++axis) X(axis, a) = corner[a][axis] * spacing[axis];
            }
            Mat3 Dm;
            for (int a = 0; a < 3; ++a) Dm.col(a) = X.col(a + 1) - X.col(0);
            // Odd permutations give negative orientation: swap two nodes to make det D_m > 0.
            if (Dm.determinant() < 0) {
              std::swap(node[1], node[2]);
              Dm.col(0).swap(Dm.col(1));
            }
            tet.volume = Dm.determinant() / 6;
            const Mat3 Dm_inv = Dm.inverse();
            tet.G.row(0) = -Dm_inv.colwise().sum();
            tet.G.bottomRows<3>() = Dm_inv;
            for (int a = 0; a < 4; ++a) {
              tet.dof[a] = node_dof[node[a]];
              if (tet.dof[a] >= 0) {
                lumped.segment<3>(tet.dof[a]).array() += config_.density * tet.volume / 4;
              }
            }
            tets_.push_back(tet);
          }
        }
      }
    }
    set_mass(lumped);
    build_pattern();
  }

  void build_initial_state() {
    const double L = config_.length;
    const Vec3 axis_point(0, 0.5 * config_.width, 0.5 * config_.height);
    initial_.t = 0;
    initial_.q = rest_q_;
    initial_.p = Vec::Zero(dof());
    // Spin about the bar's centre when free, about the clamped face's centre when clamped; the
    // tilted axis (1, 1, 1)/√3 exercises every angular momentum component.
    const Vec3 centre = config_.face_held()                      ? axis_point
                        : config_.clamp == Clamp::kPinConstraint ? Vec3::Zero().eval()
                                                                 : axis_point + Vec3(0.5 * L, 0, 0);
    const Vec3 omega = config_.spin / std::sqrt(3.0) * Vec3::Ones();
    for (int i = 0; i < dof(); i += 3) {
      const Vec3 X = rest_q_.segment<3>(i);
      const double s = X.x() / L;
      switch (config_.init) {
        case Init::kRest:
          break;
        case Init::kTwist: {
          // Rotate the cross-section about the bar axis by twist·x/L.
          const double angle = config_.twist * s;
          const double y = X.y() - axis_point.y(), z = X.z() - axis_point.z();
          initial_.q[i + 1] = axis_point.y() + std::cos(angle) * y - std::sin(angle) * z;
          initial_.q[i + 2] = axis_point.z() + std::sin(angle) * y + std::cos(angle) * z;
          break;
        }
        case Init::kBend:
          initial_.q[i + 2] += config_.bend * s * s;
          break;
        case Init::kVelocity: {
          Vec3 v = omega.cross(X - centre);
          v.z() += config_.shake * s * s;
          initial_.p.segment<3>(i) = mass()[i] * v;
          break;
        }
      }
    }
    // Consistent start (g = 0, G v = 0): pinned nodes at rest where they are pinned. Every
    // init leaves the face x = 0 in place; only the spin moves it.
    for (int d : pinned_dofs_) initial_.p.segment<3>(d).setZero();
  }

  BarConfig config_;
  double mu_, lambda_;
  std::vector<Tet> tets_;
  std::vector<int> free_node_;                   // free index → mesh node
  std::vector<int> tip_dofs_;                    // first dof of each node on the face x = length
  std::vector<int> pinned_nodes_, pinned_dofs_;  // nodes held by constraints, their first dof
  Vec rest_q_;                      // rest positions of the free nodes, laid out like q
  SparseMatrix pattern_;            // structure of K with zero values
  std::vector<int> first_element_;  // per free node, the first element that holds it
  State initial_;
};

}  // namespace

std::size_t elastic_bar_footprint_bytes(const Problem& problem) {
  const auto* bar = dynamic_cast<const ElasticBar*>(&problem);
  return bar == nullptr ? 0 : bar->footprint_bytes();
}

std::unique_ptr<Problem> make_elastic_bar(Params& params) {
  // 10⁶ cells = 6·10⁶ tetrahedra, ~2 GB of element data and Hessian pattern (~136 B per element,
  // ~135 Hessian entries per node); the entry count stays well inside Eigen's int index.
  constexpr long kMaxCells = 1'000'000;
  BarConfig config;
  config.nx = static_cast<int>(params.integer("nx", 8, "cells along the bar (x)", 1, kMaxCells));
  config.ny = static_cast<int>(params.integer("ny", 2, "cells across the width (y)", 1, kMaxCells));
  config.nz =
      static_cast<int>(params.integer("nz", 2, "cells across the height (z)", 1, kMaxCells));
  if (static_cast<double>(config.nx) * config.ny * config.nz > kMaxCells) {
    throw InputError(
        fmt::format("problem 'elastic_bar': parameters nx={}, ny={}, nz={} give more than {} cells",
                    config.nx, config.ny, config.nz, kMaxCells));
  }
  config.length = params.real("length", 1.0, "bar length (x)", Range::above(0));
  config.width = params.real("width", 0.2, "bar width (y)", Range::above(0));
  config.height = params.real("height", 0.2, "bar height (z)", Range::above(0));
  config.material = params.choice("material", "neohookean", {"stvk", "neohookean"},
                                  "hyperelastic energy W(F)") == "stvk"
                        ? Material::kStvk
                        : Material::kNeoHookean;
  config.young = params.real("young", 1e5, "Young's modulus E", Range::above(0));
  config.poisson = params.real("poisson", 0.3, "Poisson's ratio", Range::closed_open(0, 0.5));
  config.density = params.real("density", 1000.0, "mass density rho", Range::above(0));
  const std::string clamp = params.choice(
      "clamp", "left", {"left", "none", "constraint", "pin"},
      "left: nodes at x = 0 fixed (removed); none: free; constraint: nodes at x = 0 pinned by "
      "constraints q - X = 0; pin: the corner node at the origin pinned by constraints");
  config.clamp = clamp == "left"         ? Clamp::kLeft
                 : clamp == "none"       ? Clamp::kNone
                 : clamp == "constraint" ? Clamp::kFaceConstraint
                                         : Clamp::kPinConstraint;
  // Gravity breaks translation invariance, so a free bar gets none (its default is 0) and asking
  // for it is an error rather than a silent loss of the momentum checks.
  config.gravity = params.real(
      "gravity", config.face_held() ? 9.81 : 0.0,
      "gravitational acceleration along -z (default 9.81 with a held face, 0 free or pinned)");
  if (config.clamp == Clamp::kNone && config.gravity != 0) {
    throw InputError(fmt::format(
        "problem 'elastic_bar': parameter gravity={} needs clamp=left (a free bar under gravity "
        "conserves no momentum; use gravity=0 with clamp=none)",
        format_number(config.gravity)));
  }
  config.damping =
      params.real("damping", 0.0, "strain-rate damping nu (time units)", Range::at_least(0));
  const std::string init = params.choice("init", config.face_held() ? "rest" : "velocity",
                                         {"rest", "twist", "bend", "velocity"},
                                         "initial condition (default rest clamped, velocity free)");
  config.init = init == "rest"    ? Init::kRest
                : init == "twist" ? Init::kTwist
                : init == "bend"  ? Init::kBend
                                  : Init::kVelocity;
  config.twist = params.real("twist", 0.5, "init=twist: end rotation about the axis (rad)");
  config.bend = params.real("bend", 0.05, "init=bend: tip deflection along z, shape (x/L)^2");
  config.spin = params.real("spin", 1.0, "init=velocity: angular speed about (1,1,1)/sqrt(3)");
  config.shake = params.real("shake", 0.5, "init=velocity: transverse speed along z, (x/L)^2");
  config.proj_spd = params.flag("proj_spd", false,
                                "project element Hessians to PSD (modified Newton; not exact)");
  return std::make_unique<ElasticBar>(config);
}

}  // namespace geomint
