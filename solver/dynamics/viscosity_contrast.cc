#include "solver/dynamics/viscosity_contrast.h"

#include <cmath>
#include <sstream>

namespace capsim::dynamics {

ViscosityContrast::ViscosityContrast(const mesh::SurfaceMesh& mesh, const stokes::SingleLayerOptions& layer_options,
                                     double lambda, const stokes::SecondKindOptions& options)
    : mesh_(mesh), layer_(mesh, layer_options), lambda_(lambda), options_(options) {
  if (!(lambda > 0.0) || !std::isfinite(lambda) || lambda == 1.0)
    throw std::invalid_argument("ViscosityContrast: the viscosity ratio must be a finite number > 0 other than 1");
  std::string why;
  if (!options.valid(&why)) throw std::invalid_argument("ViscosityContrast: " + why);
}

void ViscosityContrast::solve(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& f, Eigen::Matrix3Xd& v) {
  // solve_second_kind takes v as the initial guess when it is 3 × N: a cold start needs it empty.
  if (warm_)
    v = previous_;
  else
    v.resize(3, 0);
  last_ = stokes::solve_second_kind(layer_, mesh_, x, lambda_, f, v, options_);
  stats_.applications += last_.applications;
  stats_.setup_s += last_.setup_s;
  stats_.layer_prepare_s += last_.layer_prepare_s;
  stats_.layer_layout_s += last_.layer_layout_s;
  stats_.layer_regular_s += last_.layer_regular_s;
  stats_.layer_singular_s += last_.layer_singular_s;
  stats_.layer_near_s += last_.layer_near_s;
  stats_.total_s += last_.total_s;
  if (!last_.converged) {
    warm_ = false;
    std::ostringstream msg;
    msg << "viscosity-ratio solve (λ = " << lambda_ << ") did not converge: " << last_.reason << " after "
        << last_.iterations << " GMRES iterations, relative residual " << last_.residual << " > tolerance "
        << options_.tolerance;
    throw SecondKindNotConverged(msg.str());
  }
  ++stats_.solves;
  stats_.iterations += last_.iterations;
  if (last_.iterations > stats_.max_iterations) stats_.max_iterations = last_.iterations;
  previous_ = v;
  warm_ = true;
}

}  // namespace capsim::dynamics
