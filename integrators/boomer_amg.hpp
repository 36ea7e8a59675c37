// Algebraic multigrid preconditioner for the CG inside Newton: one V-cycle of hypre's BoomerAMG
// (Henson & Yang, "BoomerAMG: a parallel algebraic multigrid solver and preconditioner",
// Appl. Numer. Math. 41, 2002), HMIS coarsening, extended+i interpolation, symmetric smoothing.
#pragma once

#include <memory>

#include "problems/problem.hpp"

namespace geomint {

struct BoomerAmgOptions {
  // hypre's recommendation for 3-D problems (its default 0.25 is for 2-D): fewer, sparser
  // coarse levels.
  double strong_threshold = 0.5;
  // Unknowns per node, interleaved (x₀ y₀ z₀ x₁ …), used when it divides the size: coupling is
  // only coarsened between unknowns of the same function (hypre's "unknown approach" for
  // systems); 1 treats the matrix as scalar. Every 3-D problem of geomint stores its unknowns so;
  // for any other matrix it is merely a different SPD preconditioner (CG still solves the true
  // system). Measured on the elastic bar's midpoint matrix at 99 840 tets (bench_amg_tuning):
  // 16 CG iterations instead of 26–36 with the scalar hierarchy.
  int functions = 3;
  // Levels of aggressive coarsening from the finest: the set-up ~2–3× cheaper and each V-cycle
  // ~2× cheaper for ~1.6× the CG iterations (bench_amg_tuning, 99 840 tets: set-up 110–180 ms
  // against 180–350 ms).
  int aggressive_levels = 1;
};

class BoomerAmg {
 public:
  explicit BoomerAmg(BoomerAmgOptions options = {});
  ~BoomerAmg();
  BoomerAmg(const BoomerAmg&) = delete;
  BoomerAmg& operator=(const BoomerAmg&) = delete;

  // Builds the multigrid hierarchy of the symmetric matrix whose lower triangle is `lower` (the
  // triangle the Cholesky solvers and the CG read). False when hypre reports an error; the
  // hierarchy held before is dropped either way.
  bool setup(const SparseMatrix& lower);
  // One V-cycle from zero on A z = r: z ≈ A⁻¹r, an SPD operator when A is SPD (forward
  // Gauss–Seidel down, backward up).
  Vec solve(const Vec& r) const;
  bool ready() const;
  Eigen::Index rows() const;

 private:
  struct Hierarchy;
  BoomerAmgOptions options_;
  std::unique_ptr<Hierarchy> hierarchy_;
};

}  // namespace geomint
