// The elastic bar's one entry point beyond the registry (docs/METHOD.md §6): the memory of its
// precomputed mesh data, reported by bench/bench_elastic_bar.cpp as a counter.
#pragma once

#include <cstddef>

#include "problems/problem.hpp"

namespace geomint {

// Bytes held by an elastic_bar's element data and Hessian pattern; 0 for any other problem.
std::size_t elastic_bar_footprint_bytes(const Problem& problem);

}  // namespace geomint
