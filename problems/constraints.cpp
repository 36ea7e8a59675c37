// The defaults of the holonomic-constraint interface (problems/constraints.hpp): generic multiplier
// names, time-free rheonomic functions with zero time terms, no exact multipliers.
#include "problems/constraints.hpp"

#include <fmt/format.h>

namespace geomint {

std::vector<std::string> HolonomicConstraints::multiplier_names() const {
  std::vector<std::string> names;
  for (int i = 1; i <= constraint_count(); ++i) names.push_back(fmt::format("lambda{}", i));
  return names;
}

void HolonomicConstraints::constraint_at(double, const Vec& q, Vec& g) const { constraint(q, g); }
void HolonomicConstraints::constraint_jacobian_at(double, const Vec& q, SparseMatrix& G) const {
  constraint_jacobian(q, G);
}
void HolonomicConstraints::constraint_time_terms(double, const Vec&, const Vec&, Vec& g_t,
                                                 Vec& a_t) const {
  g_t = Vec::Zero(constraint_count());
  a_t = Vec::Zero(constraint_count());
}

std::optional<Vec> HolonomicConstraints::exact_multipliers(double) const { return std::nullopt; }

}  // namespace geomint
