#pragma once
/// @file
/// @brief The SecondKindSolve of a viscosity ratio λ ≠ 1 (flow.viscosity_ratio): GMRES with Wielandt deflation
/// (stokes::solve_second_kind) on the double layer of the capsule's mesh, warm-started within a time step
/// (solver/README.md §3b).

#include <memory>
#include <stdexcept>
#include <string>

#include <Eigen/Core>

#include "solver/dynamics/capsule_flow.h"
#include "solver/mesh/mesh.h"
#include "solver/stokes/double_layer.h"
#include "solver/stokes/second_kind_solve.h"
#include "solver/stokes/single_layer.h"

namespace capsim::dynamics {

/// @brief A second-kind solve that did not reach its tolerance (iteration limit, breakdown, non-finite residual):
/// a numerical outcome of the case, recorded by the driver as `unstable` with what() as the reason.
class SecondKindNotConverged : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// @brief (1 + λ)/2 · v − (1 − λ)/(8π) · D_x[v] = f by stokes::solve_second_kind on a DoubleLayer of the mesh with
/// the single layer's quadrature and symmetry options (both layers integrate on the same rules).
///
/// Warm start: every solve after the first of a time step starts from the previous solve's v (the stages of one
/// step differ little); begin_step() forgets it, so the first solve of each step starts from zero and a resumed
/// run repeats an uninterrupted one bitwise. A solve that does not converge throws SecondKindNotConverged (the
/// CapsuleFlow contract) and does not become a warm start.
class ViscosityContrast final : public SecondKindSolve {
 public:
  /// @param mesh the CapsuleFlow's mesh (referenced, must outlive this object)
  /// @throws std::invalid_argument if λ is not in (0, ∞), λ = 1, or the options are invalid.
  ViscosityContrast(const mesh::SurfaceMesh& mesh, const stokes::SingleLayerOptions& layer_options, double lambda,
                    const stokes::SecondKindOptions& options);

  void solve(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& f, Eigen::Matrix3Xd& v) override;
  void begin_step() override { warm_ = false; }

  [[nodiscard]] double viscosity_ratio() const { return lambda_; }
  [[nodiscard]] SecondKindStatistics statistics() const override { return stats_; }
  [[nodiscard]] const stokes::SecondKindResult& last_result() const { return last_; }

 private:
  const mesh::SurfaceMesh& mesh_;
  stokes::DoubleLayer layer_;
  double lambda_;
  stokes::SecondKindOptions options_;
  Eigen::Matrix3Xd previous_;  // v of the last converged solve of this step
  bool warm_ = false;          // previous_ is a warm start for the next solve
  stokes::SecondKindResult last_;
  SecondKindStatistics stats_;
};

}  // namespace capsim::dynamics
