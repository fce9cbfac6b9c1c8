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

/// @brief The points of `rule` on every element, element-major (element e's points at [e·nq, e·nq + nq)), as
/// double-layer sources: position, density v and weighted normal. No padding (the blocks are summed per element
/// or over the whole range by add_double_layer_block). OpenMP-parallel over elements.
void layout_normal_points(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                          const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, NormalSourceArrays& out);

/// @brief The density part of layout_normal_points alone: out.vx, vy, vz at the points of `rule` on every element
/// (the P2 interpolant Σ_a N_a v_a), element-major; positions and normals are left as they are (the double layer
/// lays them out once per surface and the density once per application).
void layout_density(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                    const Eigen::Matrix3Xd& v, NormalSourceArrays& out);

/// @brief acc += sign · Σ_{p ∈ [begin, end)} (v_p − v0)·T(x_p − x0)·n_p (kernel::add_stresslet) for one target
/// x0 with density v0 (vectorised over p; a source at the target contributes nothing).
inline void add_double_layer_block(const double x0[3], const double v0[3], const NormalSourceArrays& s, int begin,
                                   int end, double sign, double acc[3]) {
  const double *px = s.x.data(), *py = s.y.data(), *pz = s.z.data();
  const double *vx = s.vx.data(), *vy = s.vy.data(), *vz = s.vz.data();
  const double *nx = s.nx.data(), *ny = s.ny.data(), *nz = s.nz.data();
  double ax = 0.0, ay = 0.0, az = 0.0;
#pragma omp simd reduction(+ : ax, ay, az)
  for (int p = begin; p < end; ++p) {
    const double rx = px[p] - x0[0], ry = py[p] - x0[1], rz = pz[p] - x0[2];
    const double r2 = rx * rx + ry * ry + rz * rz;
    const double inv = r2 == 0.0 ? 0.0 : kernel::rsqrt_arith(r2);
    kernel::add_stresslet(rx, ry, rz, vx[p] - v0[0], vy[p] - v0[1], vz[p] - v0[2], nx[p], ny[p], nz[p], inv, ax, ay,
                          az);
  }
  acc[0] += sign * ax;
  acc[1] += sign * ay;
  acc[2] += sign * az;
}

/// @brief Lanes of add_double_layer_blocks: the block length must be a multiple of it.
inline constexpr int kDoubleLayerLanes = 8;

/// @brief acc += Σ_k Σ_{p ∈ [begins[k], begins[k] + length)} (v_p − v0)·T(x_p − x0)·n_p: one target against `count`
/// short blocks of sources (the near-singular correction: the subdivided rule of each neighbouring element), the
/// kDoubleLayerLanes lanes accumulated over all blocks and reduced once (per-block reductions cost as much as the
/// terms of such short blocks). Requires length to be a multiple of kDoubleLayerLanes (pad each block with
/// zero-weight points: n = 0).
inline void add_double_layer_blocks(const double x0[3], const double v0[3], const NormalSourceArrays& s,
                                    const int* begins, int count, int length, double acc[3]) {
  constexpr int kL = kDoubleLayerLanes;
  const double *px = s.x.data(), *py = s.y.data(), *pz = s.z.data();
  const double *vx = s.vx.data(), *vy = s.vy.data(), *vz = s.vz.data();
  const double *nx = s.nx.data(), *ny = s.ny.data(), *nz = s.nz.data();
  alignas(64) double ax[kL] = {}, ay[kL] = {}, az[kL] = {};
  for (int k = 0; k < count; ++k)
    for (int j = begins[k]; j < begins[k] + length; j += kL) {
#pragma omp simd aligned(ax, ay, az : 64)
      for (int l = 0; l < kL; ++l) {
        const int p = j + l;
        const double rx = px[p] - x0[0], ry = py[p] - x0[1], rz = pz[p] - x0[2];
        const double r2 = rx * rx + ry * ry + rz * rz;
        const double inv = r2 == 0.0 ? 0.0 : kernel::rsqrt_arith(r2);
        kernel::add_stresslet(rx, ry, rz, vx[p] - v0[0], vy[p] - v0[1], vz[p] - v0[2], nx[p], ny[p], nz[p], inv,
                              ax[l], ay[l], az[l]);
      }
    }
  for (int l = 0; l < kL; ++l) {
    acc[0] += ax[l];
    acc[1] += ay[l];
    acc[2] += az[l];
  }
}

/// @brief The points of `a`, then those of `b` with negated weights: one contiguous block per element that
/// replaces rule b by rule a (used by the near-singular correction and the far-field tier).
std::vector<mesh::P2Point> replace_rule(const std::vector<mesh::P2Point>& a, const std::vector<mesh::P2Point>& b);

}  // namespace capsim::stokes
