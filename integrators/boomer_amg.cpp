// hypre BoomerAMG as a CG preconditioner (see boomer_amg.hpp), on one process: Debian's hypre
// is built with MPI (HYPRE_HAVE_MPI), so MPI is initialised once, as a singleton, on first use.
#include "integrators/boomer_amg.hpp"

// Open MPI's C++ bindings are deprecated and need libmpi_cxx; only the C interface is used.
#define OMPI_SKIP_MPICXX 1
#include <HYPRE.h>
#include <HYPRE_IJ_mv.h>
#include <HYPRE_parcsr_ls.h>
#include <HYPRE_utilities.h>
#include <mpi.h>

#include <cstdlib>
#include <mutex>
#include <numeric>
#include <vector>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GEOMINT_LEAK_CHECKED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define GEOMINT_LEAK_CHECKED 1
#endif
#ifdef GEOMINT_LEAK_CHECKED
#include <sanitizer/lsan_interface.h>
#endif

namespace geomint {
namespace {

// hypre's parallel matrices call MPI even on MPI_COMM_SELF, and Open MPI aborts a call made
// before MPI_Init. A singleton MPI_Init costs ~0.6 s when it starts Open MPI's runtime daemon;
// isolated singleton mode with only the self transport (the process never talks to another)
// takes ~0.1 s. Explicit OMPI_MCA_* settings in the environment win (setenv does not overwrite).
// MPI_Finalize is never called: it would unload Open MPI's plug-ins while static objects
// may still hold hypre data, and a singleton exits cleanly without it.
void ensure_mpi_initialised() {
  static std::once_flag once;
  std::call_once(once, [] {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) {
      setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
      setenv("OMPI_MCA_btl", "self", 0);
      setenv("OMPI_MCA_pml", "ob1", 0);
#ifdef GEOMINT_LEAK_CHECKED
      // Open MPI keeps start-up allocations for the life of the process; they are not ours.
      __lsan::ScopedDisabler not_our_allocations;
#endif
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SINGLE, &provided);
    }
    HYPRE_Init();
  });
}

}  // namespace

struct BoomerAmg::Hierarchy {
  HYPRE_IJMatrix matrix = nullptr;
  HYPRE_IJVector rhs = nullptr;
  HYPRE_IJVector solution = nullptr;
  HYPRE_Solver amg = nullptr;
  HYPRE_ParCSRMatrix par_matrix = nullptr;
  HYPRE_ParVector par_rhs = nullptr;
  HYPRE_ParVector par_solution = nullptr;
  std::vector<HYPRE_BigInt> indices;  // 0 … n−1, for the vector copies
  bool ready = false;

  ~Hierarchy() { release(); }

  void release() {
    if (amg) HYPRE_BoomerAMGDestroy(amg);
    if (matrix) HYPRE_IJMatrixDestroy(matrix);
    if (rhs) HYPRE_IJVectorDestroy(rhs);
    if (solution) HYPRE_IJVectorDestroy(solution);
    amg = nullptr;
    matrix = nullptr;
    rhs = solution = nullptr;
    ready = false;
  }

  static HYPRE_IJVector make_vector(HYPRE_BigInt n) {
    HYPRE_IJVector v = nullptr;
    HYPRE_IJVectorCreate(MPI_COMM_SELF, 0, n - 1, &v);
    HYPRE_IJVectorSetObjectType(v, HYPRE_PARCSR);
    HYPRE_IJVectorInitialize(v);
    return v;
  }
};

BoomerAmg::BoomerAmg(BoomerAmgOptions options)
    : options_(options), hierarchy_(std::make_unique<Hierarchy>()) {}
BoomerAmg::~BoomerAmg() = default;

bool BoomerAmg::ready() const { return hierarchy_->ready; }
Eigen::Index BoomerAmg::rows() const {
  return static_cast<Eigen::Index>(hierarchy_->indices.size());
}

bool BoomerAmg::setup(const SparseMatrix& lower) {
  ensure_mpi_initialised();
  Hierarchy& h = *hierarchy_;
  h.release();
  const HYPRE_BigInt n = lower.rows();
  h.indices.resize(static_cast<std::size_t>(n));
  std::iota(h.indices.begin(), h.indices.end(), HYPRE_BigInt{0});
  if (n == 0) return false;

  // Both triangles, row by row: a column-major symmetric matrix is its own row-major transpose.
  SparseMatrix full = lower.selfadjointView<Eigen::Lower>();
  full.makeCompressed();
  std::vector<HYPRE_Int> row_sizes(static_cast<std::size_t>(n));
  for (HYPRE_BigInt i = 0; i < n; ++i) {
    row_sizes[static_cast<std::size_t>(i)] = full.outerIndexPtr()[i + 1] - full.outerIndexPtr()[i];
  }
  std::vector<HYPRE_BigInt> columns(full.innerIndexPtr(), full.innerIndexPtr() + full.nonZeros());

  int errors = 0;
  errors |= HYPRE_IJMatrixCreate(MPI_COMM_SELF, 0, n - 1, 0, n - 1, &h.matrix);
  errors |= HYPRE_IJMatrixSetObjectType(h.matrix, HYPRE_PARCSR);
  errors |= HYPRE_IJMatrixSetRowSizes(h.matrix, row_sizes.data());
  errors |= HYPRE_IJMatrixInitialize(h.matrix);
  errors |= HYPRE_IJMatrixSetValues(h.matrix, static_cast<HYPRE_Int>(n), row_sizes.data(),
                                    h.indices.data(), columns.data(), full.valuePtr());
  errors |= HYPRE_IJMatrixAssemble(h.matrix);
  errors |= HYPRE_IJMatrixGetObject(h.matrix, reinterpret_cast<void**>(&h.par_matrix));
  h.rhs = Hierarchy::make_vector(n);
  h.solution = Hierarchy::make_vector(n);
  errors |= HYPRE_IJVectorAssemble(h.rhs);
  errors |= HYPRE_IJVectorAssemble(h.solution);
  errors |= HYPRE_IJVectorGetObject(h.rhs, reinterpret_cast<void**>(&h.par_rhs));
  errors |= HYPRE_IJVectorGetObject(h.solution, reinterpret_cast<void**>(&h.par_solution));

  errors |= HYPRE_BoomerAMGCreate(&h.amg);
  HYPRE_BoomerAMGSetPrintLevel(h.amg, 0);
  // A preconditioner: exactly one V-cycle per application, from a zero initial guess.
  HYPRE_BoomerAMGSetMaxIter(h.amg, 1);
  HYPRE_BoomerAMGSetTol(h.amg, 0.0);
  HYPRE_BoomerAMGSetStrongThreshold(h.amg, options_.strong_threshold);
  if (options_.functions > 1 && n % options_.functions == 0) {
    HYPRE_BoomerAMGSetNumFunctions(h.amg, options_.functions);
  }
  if (options_.aggressive_levels > 0) {
    HYPRE_BoomerAMGSetAggNumLevels(h.amg, options_.aggressive_levels);
  }
  errors |= HYPRE_BoomerAMGSetup(h.amg, h.par_matrix, h.par_rhs, h.par_solution);
  if (errors != 0) {
    HYPRE_ClearAllErrors();
    h.release();
    return false;
  }
  h.ready = true;
  return true;
}

Vec BoomerAmg::solve(const Vec& r) const {
  Hierarchy& h = *hierarchy_;
  const auto n = static_cast<HYPRE_Int>(r.size());
  Vec z = Vec::Zero(r.size());
  HYPRE_IJVectorSetValues(h.rhs, n, h.indices.data(), r.data());
  HYPRE_IJVectorSetValues(h.solution, n, h.indices.data(), z.data());
  HYPRE_BoomerAMGSolve(h.amg, h.par_matrix, h.par_rhs, h.par_solution);
  HYPRE_IJVectorGetValues(h.solution, n, h.indices.data(), z.data());
  // The V-cycle reports "not converged" (it never is after one cycle with tolerance 0).
  HYPRE_ClearAllErrors();
  return z;
}

}  // namespace geomint
