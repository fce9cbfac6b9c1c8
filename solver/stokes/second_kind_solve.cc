#include "solver/stokes/second_kind_solve.h"

#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/QR>

namespace capsim::stokes {
namespace {

using Vec = Eigen::VectorXd;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool fail(std::string* why, const std::string& message) {
  if (why != nullptr) *why = message;
  return false;
}

// Â w = w − κ (K w + Q Qᵀ w − u aᵀ w), K = D/4π (the deflation terms only when `deflate`): the matrix of the
// solve, applied to flat nodal vectors (x1, y1, z1, x2, ...: the layout of a Matrix3Xd).
class SystemOperator {
 public:
  SystemOperator(DoubleLayer& layer, const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double kappa,
                 bool deflate)
      : layer_(layer), x_(x), kappa_(kappa), deflate_(deflate) {
    layer_.forget_surface();  // prepared by the first application (its cost is the solve's)
    if (!deflate_) return;
    const Eigen::Index n = x.cols();
    // The six rigid motions at the nodes (translations e_k, rotations e_k × x), orthonormalised.
    Eigen::MatrixXd rigid = Eigen::MatrixXd::Zero(3 * n, 6);
    for (Eigen::Index i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        rigid(3 * i + k, k) = 1.0;
        const Eigen::Vector3d rot = Eigen::Vector3d::Unit(k).cross(Eigen::Vector3d(x.col(i)));
        rigid.block<3, 1>(3 * i, 3 + k) = rot;
      }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(rigid);
    q_ = qr.householderQ() * Eigen::MatrixXd::Identity(3 * n, 6);
    // The volume mode: left vector a (the flux), right vector u = n_h / (aᵀ n_h).
    // Both in one pass over the elements (a = DoubleLayer::flux_weights).
    Eigen::Matrix3Xd normals, a;
    std::vector<double> scratch;
    mesh::node_normals_and_flux_moments(mesh, x, normals, a, scratch);
    a_ = Eigen::Map<const Vec>(a.data(), 3 * n);
    u_ = Eigen::Map<const Vec>(normals.data(), 3 * n);
    u_ /= a_.dot(u_);
  }

  Vec apply(const Vec& w) {
    const Eigen::Index n = x_.cols();
    density_ = Eigen::Map<const Eigen::Matrix3Xd>(w.data(), 3, n);
    layer_.apply(x_, density_, result_);
    const DoubleLayerStats& st = layer_.last_stats();
    prepare_s += st.prepare_s;
    layout_s += st.build_s;
    regular_s += st.regular_s;
    singular_s += st.singular_s;
    near_s += st.near_s;
    Vec kw = Eigen::Map<const Vec>(result_.data(), 3 * n) / (4.0 * std::numbers::pi);
    if (deflate_) kw += q_ * (q_.transpose() * w) - u_ * a_.dot(w);
    return w - kappa_ * kw;
  }

  // Time in the applications of D, by DoubleLayerStats phase (seconds, summed).
  double prepare_s = 0.0, layout_s = 0.0, regular_s = 0.0, singular_s = 0.0, near_s = 0.0;

  // Q Qᵀ w (the rigid-motion part of w).
  [[nodiscard]] Vec rigid_part(const Vec& w) const { return q_ * (q_.transpose() * w); }

 private:
  DoubleLayer& layer_;
  const Eigen::Matrix3Xd& x_;
  double kappa_;
  bool deflate_;
  Eigen::MatrixXd q_;
  Vec a_, u_;
  Eigen::Matrix3Xd density_, result_;
};

// Givens rotation (c, s) that maps (p, q) to (hypot(p, q), 0).
void givens(double p, double q, double& c, double& s) {
  if (q == 0.0) {
    c = 1.0;
    s = 0.0;
    return;
  }
  const double h = std::hypot(p, q);
  c = p / h;
  s = q / h;
}

// Restarted GMRES(m) with modified Gram-Schmidt on op w = g from w (updated in place). The residual vector is
// carried through the Arnoldi relation r ← r − V_{j+1} H̄ y (no extra application per restart).
void gmres(SystemOperator& op, const Vec& g, Vec& w, bool warm, const SecondKindOptions& opt, SecondKindResult& out) {
  const double gnorm = g.norm();
  if (!std::isfinite(gnorm)) {
    out.reason = "non-finite residual";
    out.residual = gnorm;
    return;
  }
  if (gnorm == 0.0) {
    w.setZero();
    out.converged = true;
    out.reason = "converged";
    return;
  }
  Vec r = g;
  if (warm) {
    r -= op.apply(w);
    ++out.applications;
  } else {
    w.setZero();
  }
  // Whether the solve ends at the residual norm b: not finite, or converged (then with `why`).
  auto settled = [&](double b, const char* why) {
    out.residual = b / gnorm;
    if (!std::isfinite(out.residual)) {
      out.reason = "non-finite residual";
      return true;
    }
    if (out.residual > opt.tolerance) return false;
    out.converged = true;
    out.reason = why;
    return true;
  };
  double beta = r.norm();
  if (settled(beta, "initial guess already converged")) return;
  const int m = opt.restart;
  const Eigen::Index size = g.size();
  Eigen::MatrixXd basis(size, m + 1), hess(m + 1, m), rot(m + 1, m);
  Vec s(m + 1), cs(m), sn(m);
  while (true) {
    basis.col(0) = r / beta;
    s.setZero();
    s(0) = beta;
    hess.setZero();
    int j = 0;
    bool breakdown = false;
    while (j < m && out.iterations < opt.max_iterations) {
      Vec z = op.apply(basis.col(j));
      ++out.iterations;
      ++out.applications;
      const double znorm = z.norm();  // |Â v_j|, the scale of the breakdown test below
      for (int i = 0; i <= j; ++i) {
        hess(i, j) = basis.col(i).dot(z);
        z -= hess(i, j) * basis.col(i);
      }
      hess(j + 1, j) = z.norm();
      rot.col(j) = hess.col(j);
      for (int i = 0; i < j; ++i) {
        const double t = cs(i) * rot(i, j) + sn(i) * rot(i + 1, j);
        rot(i + 1, j) = -sn(i) * rot(i, j) + cs(i) * rot(i + 1, j);
        rot(i, j) = t;
      }
      givens(rot(j, j), rot(j + 1, j), cs(j), sn(j));
      rot(j, j) = cs(j) * rot(j, j) + sn(j) * rot(j + 1, j);
      rot(j + 1, j) = 0.0;
      s(j + 1) = -sn(j) * s(j);
      s(j) = cs(j) * s(j);
      ++j;
      // A (near) invariant Krylov space: the solution lies in it (|v_j| = 1, so the test is relative to |Â v_j|).
      breakdown = !(hess(j, j - 1) > 1e-14 * znorm);
      if (breakdown) {
        basis.col(j).setZero();
        break;
      }
      basis.col(j) = z / hess(j, j - 1);
      if (!(std::abs(s(j)) / gnorm > opt.tolerance)) break;  // converged (or NaN: caught below)
    }
    const Vec y = rot.topLeftCorner(j, j).triangularView<Eigen::Upper>().solve(s.head(j));
    w += basis.leftCols(j) * y;
    r = beta * basis.col(0) - basis.leftCols(j + 1) * (hess.topLeftCorner(j + 1, j) * y);
    beta = r.norm();
    if (settled(beta, "converged")) return;
    if (breakdown) {
      out.reason = "breakdown";
      return;
    }
    if (out.iterations >= opt.max_iterations) {
      out.reason = "iteration limit";
      return;
    }
  }
}

}  // namespace

bool SecondKindOptions::valid(std::string* why) const {
  if (!(tolerance > 0.0 && tolerance < 1.0))
    return fail(why, "tolerance must be in (0, 1), got " + std::to_string(tolerance));
  if (max_iterations < 1) return fail(why, "max_iterations must be >= 1, got " + std::to_string(max_iterations));
  if (restart < 1 || restart > 500) return fail(why, "restart must be 1..500, got " + std::to_string(restart));
  return true;
}

SecondKindResult solve_second_kind(DoubleLayer& layer, const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x,
                                   double lambda, const Eigen::Matrix3Xd& f, Eigen::Matrix3Xd& v,
                                   const SecondKindOptions& options) {
  if (std::string why; !options.valid(&why)) throw std::invalid_argument("stokes: second-kind solve: " + why);
  if (!(lambda > 0.0) || !std::isfinite(lambda))
    throw std::invalid_argument("stokes: second-kind solve: the viscosity ratio must be a finite number > 0, got " +
                                std::to_string(lambda));
  const Eigen::Index n = layer.num_nodes();
  if (x.cols() != n || f.cols() != n || mesh.num_nodes() != n)
    throw std::invalid_argument("stokes: second-kind solve: x, f and the mesh must have " + std::to_string(n) +
                                " nodes");
  SecondKindResult out;
  const double kappa = (1.0 - lambda) / (1.0 + lambda);
  if (kappa == 0.0) {
    v = f;
    out.converged = true;
    out.reason = "viscosity ratio 1";
    return out;
  }
  const double t0 = now_s();
  SystemOperator op(layer, mesh, x, kappa, options.deflate);
  out.setup_s = now_s() - t0;
  const Vec g = Eigen::Map<const Vec>(f.data(), 3 * n) * (2.0 / (1.0 + lambda));
  const bool warm = v.cols() == n;
  Vec w = Vec::Zero(3 * n);
  if (warm) {
    w = Eigen::Map<const Vec>(v.data(), 3 * n);
    if (options.deflate) w += kappa * op.rigid_part(w);
  }
  gmres(op, g, w, warm, options, out);
  if (options.deflate) w -= kappa / (1.0 + kappa) * op.rigid_part(w);
  v = Eigen::Map<const Eigen::Matrix3Xd>(w.data(), 3, n);
  out.layer_prepare_s = op.prepare_s;
  out.layer_layout_s = op.layout_s;
  out.layer_regular_s = op.regular_s;
  out.layer_singular_s = op.singular_s;
  out.layer_near_s = op.near_s;
  out.total_s = now_s() - t0;
  return out;
}

}  // namespace capsim::stokes
