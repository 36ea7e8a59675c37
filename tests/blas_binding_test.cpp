// Which CBLAS GSL's linear algebra calls: GSL's own libgslcblas, whose results do not depend on
// the CPU, not OpenBLAS's run-time-dispatched kernels (problems/CMakeLists.txt says why).
#include <dlfcn.h>
#include <gsl/gsl_cblas.h>
#include <gtest/gtest.h>

#include <string>

namespace blas_binding_test {
namespace {

// The shared object that defines `symbol` in this process's global lookup scope, where GSL's own
// references to cblas_* are bound too.
std::string object_defining(const char* symbol) {
  void* address = dlsym(RTLD_DEFAULT, symbol);
  if (address == nullptr) return "(not found)";
  Dl_info info{};
  if (dladdr(address, &info) == 0 || info.dli_fname == nullptr) return "(no object)";
  return info.dli_fname;
}

TEST(BlasBinding, GslCallsItsOwnCblas) {
  // The routines GSL's LU and triangular solves (gsl_msbdf, gsl_rk4imp, gsl_bsimp) reach.
  for (const char* symbol : {"cblas_dtrsv", "cblas_dtrsm", "cblas_dgemm", "cblas_dnrm2",
                             "cblas_idamax", "cblas_dswap", "cblas_dscal"}) {
    EXPECT_NE(object_defining(symbol).find("libgslcblas"), std::string::npos)
        << symbol << " is bound to " << object_defining(symbol);
  }
}

TEST(BlasBinding, SolvesThroughItGiveTheExactAnswer) {
  // A call through the bound symbol works (the binding is not to a stub): an upper-triangular
  // solve with an exact answer. Looked up, not called by name: a direct call from this file
  // would make the linker keep libgslcblas for this test alone and hide a broken binding.
  using Trsv = void (*)(CBLAS_ORDER, CBLAS_UPLO, CBLAS_TRANSPOSE, CBLAS_DIAG, int, const double*,
                        int, double*, int);
  const auto trsv = reinterpret_cast<Trsv>(dlsym(RTLD_DEFAULT, "cblas_dtrsv"));
  ASSERT_NE(trsv, nullptr);
  const double upper[4] = {2.0, 1.0, 0.0, 4.0};
  double rhs[2] = {5.0, 8.0};
  trsv(CblasRowMajor, CblasUpper, CblasNoTrans, CblasNonUnit, 2, upper, 2, rhs, 1);
  EXPECT_EQ(rhs[0], 1.5);
  EXPECT_EQ(rhs[1], 2.0);
}

}  // namespace
}  // namespace blas_binding_test
