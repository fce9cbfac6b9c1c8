#pragma once
/// @file
/// @brief The two primitives every phase of the single-layer operator is built from (solver/README.md §3):
/// laying out the points of a rule on every element as structure-of-arrays sources (position, and load
/// weighted by the rule weight and the area element), and summing a short contiguous block of such sources
/// for one target with the scalar Stokeslet.

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/p2_tabulation.h"
#include "solver/stokes/stokeslet.h"

namespace capsim::stokes {

/// @brief Structure-of-arrays sources: positions and weighted loads w·|g1 × g2|·q.
struct SourceArrays {
  AlignedVector x, y, z, qx, qy, qz;
  /// @brief As kernel::Sources (all entries, padding included).
  [[nodiscard]] kernel::Sources sources() const {
    return {x.data(), y.data(), z.data(), qx.data(), qy.data(), qz.data(), static_cast<int>(x.size())};
  }
};

/// @brief The points of `rule` on every element, element-major (element e's points at [e·nq, e·nq + nq)),
/// padded with zero loads to a multiple of `width`. Positions and loads are the P2 interpolants of x and q.
/// OpenMP-parallel over elements.
void layout_points(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                   const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, int width, SourceArrays& out);

/// @brief acc += sign · Σ_{p ∈ [begin, end)} J(x0, x_p)·wq_p for a short contiguous block of sources
/// (vectorised over p; a source at the target contributes nothing).
inline void add_block(const double x0[3], const double* px, const double* py, const double* pz, const double* qx,
                      const double* qy, const double* qz, int begin, int end, double sign, double acc[3]) {
  double ax = 0.0, ay = 0.0, az = 0.0;
#pragma omp simd reduction(+ : ax, ay, az)
  for (int p = begin; p < end; ++p) {
    const double dx = x0[0] - px[p], dy = x0[1] - py[p], dz = x0[2] - pz[p];
    const double r2 = dx * dx + dy * dy + dz * dz;
    const double inv = r2 == 0.0 ? 0.0 : kernel::rsqrt_arith(r2);
    kernel::add_stokeslet(dx, dy, dz, qx[p], qy[p], qz[p], inv, 1.0, ax, ay, az);
  }
  acc[0] += sign * ax;
  acc[1] += sign * ay;
  acc[2] += sign * az;
}

/// @brief add_block over a SourceArrays.
inline void add_block(const double x0[3], const SourceArrays& s, int begin, int end, double sign, double acc[3]) {
  add_block(x0, s.x.data(), s.y.data(), s.z.data(), s.qx.data(), s.qy.data(), s.qz.data(), begin, end, sign, acc);
}

/// @brief Structure-of-arrays sources of the double layer (double_layer.h): positions x, the density v (the P2
/// interpolant of the nodal field) and the weighted normals w·(g1 × g2) (outward normal × area element × weight).
struct NormalSourceArrays {
  AlignedVector x, y, z, vx, vy, vz, nx, ny, nz;
};

/// @brief The geometry of the points of `rule` on every element, element-major (element e's points at [e·nq,
/// e·nq + nq)), as double-layer sources: position and weighted normal (the density arrays are left to
/// layout_density, which fills them per application). No padding. OpenMP-parallel over elements.
void layout_normal_points(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                          const Eigen::Matrix3Xd& x, NormalSourceArrays& out);

/// @brief The density part of layout_normal_points alone: out.vx, vy, vz at the points of `rule` on every element
/// (the P2 interpolant Σ_a N_a v_a), element-major; positions and normals are left as they are (the double layer
/// lays them out once per surface and the density once per application).
void layout_density(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                    const Eigen::Matrix3Xd& v, NormalSourceArrays& out);

/// @brief The points of `a`, then those of `b` with negated weights: one contiguous block per element that
/// replaces rule b by rule a (used by the near-singular correction and the far-field tier).
std::vector<mesh::P2Point> replace_rule(const std::vector<mesh::P2Point>& a, const std::vector<mesh::P2Point>& b);

}  // namespace capsim::stokes
