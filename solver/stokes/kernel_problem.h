#pragma once
/// @file
/// @brief A ready-made Stokeslet-sum problem for benchmarks and `capsim bench kernel`: the targets are the
/// nodes of the unit-sphere mesh of a level, the sources all regular quadrature points of that mesh with a
/// smooth non-uniform load (so no target sees a vanishing sum). Plain std::vector storage only, so the
/// problem can cross library boundaries built with different instruction sets.

#include "solver/stokes/stokeslet.h"

namespace capsim::stokes {

/// @brief Targets and sources as structure-of-arrays (sources padded to the SIMD width with zero load).
struct KernelProblem {
  AlignedVector tx, ty, tz;              ///< targets
  AlignedVector sx, sy, sz, qx, qy, qz;  ///< sources (padded)
  int num_sources = 0;                   ///< quadrature points without the padding

  [[nodiscard]] int num_targets() const { return static_cast<int>(tx.size()); }
  [[nodiscard]] kernel::Targets targets() const { return {tx.data(), ty.data(), tz.data(), num_targets()}; }
  [[nodiscard]] kernel::Sources sources() const {
    return {sx.data(), sy.data(), sz.data(), qx.data(), qy.data(), qz.data(), static_cast<int>(sx.size())};
  }
  /// @brief Interactions of one sum (targets × unpadded sources).
  [[nodiscard]] double interactions() const { return static_cast<double>(num_targets()) * num_sources; }
};

/// @brief The problem of sphere level `level` with the default regular rule (degree 4).
KernelProblem make_kernel_problem(int level, int regular_degree = 4);

}  // namespace capsim::stokes
