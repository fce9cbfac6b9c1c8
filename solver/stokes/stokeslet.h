#pragma once
/// @file
/// @brief Stokeslet sums, the hot loop of the boundary-integral flow (solver/README.md §3).
///
/// For targets x0_i and sources (x_j, w_j) this computes, for every target,
///     u_i = Σ_j J(x0_i, x_j) · w_j,     J = I/r + r r/r³,  r = x0_i − x_j,
/// where w_j is the already weighted load of a quadrature point (quadrature weight × surface Jacobian × q).
/// A source at zero distance from a target contributes nothing (masked lane); a NaN coordinate propagates.
///
/// Two implementations of the same sum:
///  - sum_fast: targets in SIMD lanes, one source broadcast at a time, several target vectors per tile
///    (register blocking), OpenMP static schedule over target tiles; 1/r from the hardware reciprocal
///    square-root estimate refined by one high-order Newton (Householder) step to full double accuracy,
///    alternating with the vector sqrt + division on every other target vector (InvSqrt::Hybrid: the divider
///    runs next to the FMA pipes).
///    The instruction set is chosen at compile time: AVX-512F, else AVX2+FMA, else a portable loop that
///    the compiler vectorises (see kernel_isa()).
///  - sum_plain: the reference, a straightforward `#pragma omp simd` loop over sources with 1/sqrt(r²)
///    and a division around add_stokeslet (below). Used to verify the fast kernel (tests) and as the
///    baseline of the benchmarks; SingleLayerOptions::kernel selects it for the regular sum.
/// Both overwrite u; both are OpenMP-parallel over targets (they are not meant to be called from inside a
/// parallel region; if they are, they run on the calling thread).

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

namespace capsim::stokes {

/// @brief Minimal 64-byte aligned allocator so that SoA arrays start on a cache line / vector boundary.
template <class T>
struct AlignedAllocator {
  using value_type = T;
  static constexpr std::size_t kAlign = 64;
  AlignedAllocator() noexcept = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = ((n * sizeof(T) + kAlign - 1) / kAlign) * kAlign;
    void* p = std::aligned_alloc(kAlign, bytes == 0 ? kAlign : bytes);
    if (p == nullptr) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }
  template <class U>
  bool operator==(const AlignedAllocator<U>&) const noexcept { return true; }
};

/// @brief A std::vector of doubles aligned to 64 bytes.
using AlignedVector = std::vector<double, AlignedAllocator<double>>;

namespace kernel {

/// @brief Target positions, structure of arrays (n entries each; no padding required).
struct Targets {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  int n = 0;
};

/// @brief Source positions and weighted loads, structure of arrays (n entries each). Padding entries, if
/// any, must carry a zero load.
struct Sources {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  const double* qx = nullptr;
  const double* qy = nullptr;
  const double* qz = nullptr;
  int n = 0;
};

/// @brief Output, one entry per target (n = Targets::n), overwritten.
struct Result {
  double* x = nullptr;
  double* y = nullptr;
  double* z = nullptr;
};

/// @brief How the fast kernel computes 1/r.
enum class InvSqrt {
  Newton,   ///< hardware estimate (rsqrt14 / rsqrtps) + one high-order Newton step (default)
  SqrtDiv,  ///< 1/sqrt(r²) with the vector sqrt and division instructions
  Hybrid,   ///< alternate target vectors between the two (divider and FMA pipes busy at once; block ≥ 2)
};

/// @brief Tuning of the fast kernel. The defaults are the variant measured fastest on the development machine
/// (AVX-512: hybrid, block 2); the per-variant cycle counts are in results/benchmarks.md ("Stokeslet
/// kernel"); `capsim bench kernel` and build/bin/stokes_bench re-measure them.
struct FastConfig {
  int block = 2;                        ///< target vectors per tile (1..4): register blocking
  InvSqrt inv_sqrt = InvSqrt::Hybrid;   ///< see InvSqrt
};

/// @brief The fast kernel (see the file comment). u is overwritten.
void sum_fast(const Targets& t, const Sources& s, const Result& u, const FastConfig& config = {});

/// @brief The reference `omp simd` loop (sources in lanes). u is overwritten.
void sum_plain(const Targets& t, const Sources& s, const Result& u);

/// @brief u += Σ_k Σ_{p ∈ [begins[k], begins[k] + length)} J(x0, x_p)·w_p: one target against `count` short
/// blocks of sources (the near-singular correction: the subdivided rule of each neighbouring element). Same
/// 1/r as sum_fast (hardware estimate + one Newton step), the lanes accumulated over all blocks and reduced
/// once. Requires length and every begins[k] to be multiples of simd_width() (pad each block with zero-load
/// sources); a source at the target contributes nothing. Serial: call it from the caller's parallel loop.
void sum_blocks(const double x0[3], const Sources& s, const int* begins, int count, int length, double u[3]);

/// @brief The regular sum in mixed precision (numerics.kernel_precision = "mixed"): the same sum as sum_fast,
/// with every pair term in single precision and the sums in double. Targets, sources and loads are rounded to
/// float once per call; 1/r is the float hardware estimate refined by one Newton step (relative error
/// ≈ 2e-7); each target accumulates its terms in float over blocks of kMixedBlock sources and adds the block
/// sums in double. Why it is accurate enough: the rounding of the positions (≈ 6e-8 absolute for a capsule
/// of size 1) changes a term at distance r by ≈ 6e-8/r relative, and the regular sum never sees r below
/// ≈ h/10 from a node (the Duffy and near-singular phases replace those elements; the Duffy one in float on
/// coordinates relative to the target, stokes::KernelPrecision): per target it
/// stays within kMixedRelativeBound of |u| (tests/solver/stokes/kernel_test.cc), far below the discretisation error;
/// what it moves in whole cases and campaigns is in results/speed/mixed_ab_case.json and
/// results/table1/README.md. Why it exists: twice the SIMD lanes of sum_fast and a cheaper 1/r (speed-ups in
/// results/benchmarks.md, "Mixed precision"): 16 float lanes where the build has AVX-512, 8 with AVX2. Same
/// contract as sum_fast (u overwritten, a source at zero distance contributes nothing, OpenMP-parallel over
/// targets, each target's sum independent of the thread count); NaN propagates. The two widths round
/// differently (the 1/r estimate and the order of the double sums): a case run on an AVX-512 and on an AVX2
/// build differs at round-off, as sum_fast's do; a result's kernel_isa names the build's instruction set (both
/// kernels follow the same one).
void sum_mixed(const Targets& t, const Sources& s, const Result& u);

/// @brief sum_mixed with 8 float lanes (the AVX2 tile, or the portable loop): on an AVX-512 build the variant
/// sum_mixed does not use, kept so that `capsim bench kernel` measures both and the tests hold both to the
/// contract. On other builds it is sum_mixed.
void sum_mixed_8_lanes(const Targets& t, const Sources& s, const Result& u);

/// @brief Double-layer targets: positions and the density there, structure of arrays (n entries each).
struct StressletTargets {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  const double* vx = nullptr;
  const double* vy = nullptr;
  const double* vz = nullptr;
  int n = 0;
};

/// @brief Double-layer sources: positions, density and weighted normal (weight × area element × outward normal),
/// structure of arrays (n entries each; padding entries must carry a zero normal).
struct StressletSources {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  const double* vx = nullptr;
  const double* vy = nullptr;
  const double* vz = nullptr;
  const double* nx = nullptr;
  const double* ny = nullptr;
  const double* nz = nullptr;
  int n = 0;
};

/// @brief The double layer's all-pairs regular sum (double_layer.h): for every target i
///     u_i = Σ_j (v_j − v_i)·T(x_j − x_i)·n_j     (add_stresslet),
/// a source at zero distance contributing nothing. Three implementations of the one sum, as for the Stokeslet:
///  - stresslet_sum_plain: the reference `omp simd` loop over sources (1/r by 1/std::sqrt), kept for tests;
///  - stresslet_sum_fast: the SIMD tile of stokeslet_lanes.h (targets in lanes, sources broadcast, two target
///    vectors per tile, 1/r as sum_fast's InvSqrt::Hybrid), in double (kFastRelativeBound against the plain one);
///  - stresslet_sum_mixed: the same tile in float lanes with the sums in double (numerics.double_layer_precision =
///    "mixed", as sum_mixed): targets, densities, sources and normals rounded to float once per call, partial sums
///    over kMixedBlock sources added in double. Accuracy: kStressletMixedRelativeBound.
/// All overwrite u; OpenMP-parallel over targets; each target's sum independent of the thread count.
void stresslet_sum_plain(const StressletTargets& t, const StressletSources& s, const Result& u);
/// @brief See stresslet_sum_plain.
void stresslet_sum_fast(const StressletTargets& t, const StressletSources& s, const Result& u);
/// @brief See stresslet_sum_plain.
void stresslet_sum_mixed(const StressletTargets& t, const StressletSources& s, const Result& u);

/// @brief Contract of stresslet_sum_mixed against the double sum, as max_i |Δu_i| / max_i |u_i| over the targets of
/// one evaluation (a node's own regular sum can be small where its neighbours' are not: the norm-wise measure).
/// Measured (tests/solver/stokes/double_layer_test.cc, AVX-512): 1.4e-6 on a deformed sphere and 5e-7 to 8e-7 on
/// a spheroid a/b = 2, the same at levels 2 and 3, and the same with float partial sums of 32 sources instead of
/// kMixedBlock: not the float accumulation but the rounding of positions and densities (≈ 6e-8 absolute), which
/// the stresslet feels more than the Stokeslet next to the target, where r·n = O(r²) and v − v(x0) = O(r) are
/// differences of rounded numbers. The bound leaves a factor ≈ 3 to that. Against the operator's discretisation
/// error on the sphere (solver/README.md §3b) the measured 1.4e-6 is 6e-4 of it on level 1, 1e-2 on level 2, 0.14
/// to 0.22 on level 3 and comparable on level 4: on fine meshes prefer double (numerics.kernel_precision).
inline constexpr double kStressletMixedRelativeBound = 5e-6;

/// @brief Sources a target sums in float before the partial sum is added in double (sum_mixed).
inline constexpr int kMixedBlock = 256;

/// @brief Contract of sum_mixed against the double sum: at most this relative difference per target, |Δu|/|u|,
/// on a real evaluation's distances (none below ≈ h/10). It follows from float arithmetic (a few roundings of
/// 2^-24 per term, 2e-7 for 1/r after its Newton step, kMixedBlock-term float partial sums) with room; the
/// tests and `capsim bench kernel` hold the kernel to it.
inline constexpr double kMixedRelativeBound = 1e-5;

/// @brief Contract of sum_fast against the plain double loop: relative difference per target.
inline constexpr double kFastRelativeBound = 1e-12;

/// @brief Instruction set of sum_mixed in this build: "avx512" (16 float lanes), "avx2" (8) or "portable".
const char* mixed_kernel_isa();

/// @brief Instruction set of sum_fast in this build: "avx512", "avx2" or "portable".
const char* kernel_isa();

/// @brief Number of doubles per SIMD vector of sum_fast (8, 4, or 8 for the portable loop).
int simd_width();

/// @brief 1/√x for a positive normal x, to full double accuracy, with arithmetic only: a bit-level first
/// guess (relative error ≤ 3.5%) and two Householder steps (order 5, then order 4; final error ~1e-25 before
/// rounding). Unlike 1/std::sqrt it vectorises in `omp simd` loops without -fno-math-errno. x = 0 gives a
/// large finite garbage value: mask it. NaN propagates.
inline double rsqrt_arith(double x) {
  double y = std::bit_cast<double>(std::uint64_t{0x5FE6EB50C7B537A9} - (std::bit_cast<std::uint64_t>(x) >> 1));
  double e = 1.0 - x * y * y;
  y += y * e * (0.5 + e * (0.375 + e * (0.3125 + e * (35.0 / 128.0))));
  e = 1.0 - x * y * y;
  y += y * e * (0.5 + e * (0.375 + e * 0.3125));
  return y;
}

/// @brief 1/√x in single precision for a positive normal x, with arithmetic only (the float twin of the double
/// rsqrt_arith, for `omp simd` loops of the mixed-precision corrections): a bit-level first guess (relative
/// error ≤ 3.5%), one Householder step of order 3 (→ ≤ 1e-4) and one Newton step (→ ≈ 2e-8, below float
/// rounding; tests/solver/stokes/kernel_test.cc). x = 0 gives a large finite garbage value: mask it. NaN
/// propagates.
inline float rsqrt_arith(float x) {
  float y = std::bit_cast<float>(std::uint32_t{0x5F375A86} - (std::bit_cast<std::uint32_t>(x) >> 1));
  float e = 1.0f - x * y * y;
  y += y * e * (0.5f + e * 0.375f);
  e = 1.0f - x * y * y;
  y += y * e * 0.5f;
  return y;
}

/// @brief The Stokeslet applied to a load, the one scalar definition used by every non-SIMD path:
///     u += f · (q + r (r·q) / r²),   i.e. u += w · J(r)·q with f = w / |r|,   r = x0 − x,
/// with inv_r2 = 1/r² and f supplied by the caller (each caller chooses how to compute them; inv_r2 = f = 0
/// masks a pair at zero distance). (r·q) · inv_r2 is the operation order of the SIMD tiles (stokeslet_lanes.h).
/// T is double or float (inside `omp simd` loops, where it vectorises once inlined) or long double (test
/// references).
template <class T>
inline void add_stokeslet_scaled(T rx, T ry, T rz, T qx, T qy, T qz, T inv_r2, T f, T& ux, T& uy, T& uz) {
  const T s = (rx * qx + ry * qy + rz * qz) * inv_r2;
  ux += f * (qx + rx * s);
  uy += f * (qy + ry * s);
  uz += f * (qz + rz * s);
}

/// @brief The same with inv_r = 1/|r| and the weight w: u += w · J(r)·q, J(r)·q = (q + r (r·q)/r²) / r.
template <class T>
inline void add_stokeslet(T rx, T ry, T rz, T qx, T qy, T qz, T inv_r, T w, T& ux, T& uy, T& uz) {
  add_stokeslet_scaled(rx, ry, rz, qx, qy, qz, inv_r * inv_r, w * inv_r, ux, uy, uz);
}

/// @brief The stresslet (double-layer kernel) applied to a density and a weighted normal, the one scalar
/// definition used by every double-layer loop (solver/stokes/double_layer.h):
///     u_j += d_i T_ijk(r) n_k = −6 (d·r)(r·n) r_j / |r|⁵,   T_ijk(r) = −6 r_i r_j r_k / |r|⁵,   r = x − x0,
/// with r from the target x0 to the source x (the sign convention of solver/README.md §3b: T is odd in r), d the
/// density at the source (the double layer passes v(x) − v(x0)) and n the normal at the source times its weight
/// and area element. inv_r = 1/|r| is supplied by the caller (inv_r = 0 masks a pair at zero distance). T is
/// double or float (inside `omp simd` loops) or long double (test references).
template <class T>
inline void add_stresslet(T rx, T ry, T rz, T dx, T dy, T dz, T nx, T ny, T nz, T inv_r, T& ux, T& uy, T& uz) {
  const T inv_r2 = inv_r * inv_r;
  const T s = T(-6) * (dx * rx + dy * ry + dz * rz) * (nx * rx + ny * ry + nz * rz) * (inv_r2 * inv_r2 * inv_r);
  ux += s * rx;
  uy += s * ry;
  uz += s * rz;
}

/// @brief W target lanes against the sources [j0, j1) in precision T, accumulated into a (the portable tiles of
/// sum_fast and sum_mixed, for machines without AVX2: the lane loop is what the compiler vectorises).
template <class T, int W>
inline void add_sources_to_lanes(const T* tx, const T* ty, const T* tz, const T* sx, const T* sy, const T* sz,
                                 const T* qx, const T* qy, const T* qz, int j0, int j1, T* ax, T* ay, T* az) {
  for (int j = j0; j < j1; ++j) {
    const T px = sx[j], py = sy[j], pz = sz[j], fx = qx[j], fy = qy[j], fz = qz[j];
#pragma omp simd
    for (int l = 0; l < W; ++l) {
      const T dx = tx[l] - px, dy = ty[l] - py, dz = tz[l] - pz;
      const T r2 = dx * dx + dy * dy + dz * dz;
      const T y = r2 == T(0) ? T(0) : T(1) / std::sqrt(r2);
      add_stokeslet(dx, dy, dz, fx, fy, fz, y, T(1), ax[l], ay[l], az[l]);
    }
  }
}

}  // namespace kernel
}  // namespace capsim::stokes
