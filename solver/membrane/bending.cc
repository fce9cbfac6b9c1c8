#include "solver/membrane/bending.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "solver/membrane/membrane_mechanics.h"

namespace capsim::membrane {

HelfrichBending::HelfrichBending(double modulus) : kb_(modulus) {
  if (!(modulus >= 0.0) || !std::isfinite(modulus))
    throw std::invalid_argument("bending: the modulus must be finite and >= 0, got " + std::to_string(modulus));
}

namespace {

// Geometry of the P2 map at one point: tangents, metric, area element J = |g1 × g2| and the derivatives
// ∂J/∂g1 = (g22 g1 − g12 g2)/J, ∂J/∂g2 = (g11 g2 − g12 g1)/J.
struct PointGeometry {
  Eigen::Vector3d g1, g2, m;  // m = g1 × g2 (outward normal times J)
  double g11, g12, g22, J;
  Eigen::Vector3d dJ1, dJ2;
};

bool point_geometry(const mesh::P2Tabulation& p2, const Eigen::Matrix3Xd& x, const std::array<int, 6>& el, int q,
                    PointGeometry& k) {
  const mesh::Tangents t = p2.tangents(x, el, q);
  k.g1 = t.g1;
  k.g2 = t.g2;
  k.g11 = k.g1.dot(k.g1);
  k.g12 = k.g1.dot(k.g2);
  k.g22 = k.g2.dot(k.g2);
  const double det = k.g11 * k.g22 - k.g12 * k.g12;
  if (!(det > 0.0)) return false;
  k.m = k.g1.cross(k.g2);
  k.J = std::sqrt(det);
  k.dJ1 = (k.g22 * k.g1 - k.g12 * k.g2) / k.J;
  k.dJ2 = (k.g11 * k.g2 - k.g12 * k.g1) / k.J;
  return true;
}

// Nodal sums of per-element six-node vectors, in element order (deterministic for any thread count).
Eigen::Matrix3Xd scatter(const mesh::SurfaceMesh& mesh, const std::vector<double>& per_element) {
  Eigen::Matrix3Xd out = Eigen::Matrix3Xd::Zero(3, mesh.num_nodes());
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const double* f = per_element.data() + static_cast<std::size_t>(e) * 18;
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) out(c, mesh.elements[e][a]) += f[3 * a + c];
  }
  return out;
}

[[noreturn]] void collapsed(int e) {
  throw DegenerateSurface("bending: element " + std::to_string(e) + " collapsed or non-finite");
}

}  // namespace

BendingMechanics::BendingMechanics(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& reference,
                                   HelfrichBending model, LoadSolver::Options solver_options)
    : mesh_(mesh), model_(model), p2_(mesh::P2Tabulation::of_degree(solver_options.quadrature_degree)) {
  if (reference.cols() != mesh.num_nodes())
    throw std::invalid_argument("bending: reference has " + std::to_string(reference.cols()) + " nodes, mesh has " +
                                std::to_string(mesh.num_nodes()));
  LoadSolver solver(mesh, solver_options);
  try {
    c0_ = curvature_at_points(reference, curvature_vector(reference, solver));
  } catch (const DegenerateSurface& e) {
    throw std::invalid_argument(std::string("bending: the reference surface is degenerate: ") + e.what());
  }
}

Eigen::Matrix3Xd BendingMechanics::curvature_vector(const Eigen::Matrix3Xd& x, LoadSolver& solver) const {
  // (K x)_a = ∫ ∇s φ_a · ∇s x dS = Σ_q w J (∂ξ φ_a g¹ + ∂η φ_a g²), g^α = g^{αβ} g_β the dual tangents.
  const int ne = mesh_.num_elements(), nq = p2_.size();
  std::vector<double> kx(static_cast<std::size_t>(ne) * 18, 0.0);
  int first_collapsed = ne;
#pragma omp parallel for schedule(static) reduction(min : first_collapsed)
  for (int e = 0; e < ne; ++e) {
    double* out = kx.data() + static_cast<std::size_t>(e) * 18;
    for (int q = 0; q < nq; ++q) {
      PointGeometry k;
      if (!point_geometry(p2_, x, mesh_.elements[e], q, k)) {
        first_collapsed = std::min(first_collapsed, e);
        break;
      }
      const double det = k.J * k.J, w = p2_.weight(q) * k.J;
      const Eigen::Vector3d d1 = (k.g22 * k.g1 - k.g12 * k.g2) / det, d2 = (k.g11 * k.g2 - k.g12 * k.g1) / det;
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) out[3 * a + c] += w * (p2_[q].dxi[a] * d1[c] + p2_[q].deta[a] * d2[c]);
    }
  }
  if (first_collapsed < ne) collapsed(first_collapsed);
  try {
    solver.assemble(x);
    solver.factorize();
    Eigen::Matrix3Xd h;
    solver.solve(-scatter(mesh_, kx), h);
    return h;
  } catch (const std::runtime_error& e) {
    throw DegenerateSurface(std::string("bending: ") + e.what());
  }
}

Eigen::VectorXd BendingMechanics::curvature_at_points(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& h) const {
  const int ne = mesh_.num_elements(), nq = p2_.size();
  Eigen::VectorXd c(static_cast<Eigen::Index>(ne) * nq);
  for (int e = 0; e < ne; ++e)
    for (int q = 0; q < nq; ++q) {
      PointGeometry k;
      if (!point_geometry(p2_, x, mesh_.elements[e], q, k)) collapsed(e);
      c[static_cast<Eigen::Index>(e) * nq + q] = -p2_.interpolate(h, mesh_.elements[e], q).dot(k.m) / k.J;
    }
  return c;
}

Eigen::VectorXd BendingMechanics::total_curvature(const Eigen::Matrix3Xd& x, LoadSolver& solver) const {
  return curvature_at_points(x, curvature_vector(x, solver));
}

double BendingMechanics::energy(const Eigen::Matrix3Xd& x, LoadSolver& solver) const {
  const Eigen::VectorXd c = total_curvature(x, solver);
  const int nq = p2_.size();
  double w = 0.0;
  for (int e = 0; e < mesh_.num_elements(); ++e)
    for (int q = 0; q < nq; ++q) {
      PointGeometry k;
      if (!point_geometry(p2_, x, mesh_.elements[e], q, k)) collapsed(e);
      const auto i = static_cast<Eigen::Index>(e) * nq + q;
      w += p2_.weight(q) * k.J * model_.energy_density(c[i], c0_[i]);
    }
  return w;
}

BendingState BendingMechanics::evaluate(const Eigen::Matrix3Xd& x, LoadSolver& solver) const {
  const int ne = mesh_.num_elements(), nq = p2_.size();
  const double kb = model_.modulus();
  BendingState s;
  s.internal_force = Eigen::Matrix3Xd::Zero(3, x.cols());
  if (kb == 0.0) {  // nothing to bend; the solver is still left factorised on x, as the contract says
    solver.assemble(x);
    solver.factorize();
    return s;
  }
  // Phase 1: h = −M⁻¹ K x (assembles and factorises the solver on x).
  const Eigen::Matrix3Xd h = curvature_vector(x, solver);

  // Phase 2: at every point u = J (c − c0) = −h·m − c0 J; energy, moment and the adjoint load
  // G_a = κ_b Σ_q w u n φ_a (= −∂W_b/∂h_a).
  std::vector<double> g(static_cast<std::size_t>(ne) * 18, 0.0), energy(ne, 0.0), moment(ne, 0.0);
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    const auto& el = mesh_.elements[e];
    double* out = g.data() + static_cast<std::size_t>(e) * 18;
    for (int q = 0; q < nq; ++q) {
      PointGeometry k;
      (void)point_geometry(p2_, x, el, q, k);  // not collapsed: phase 1 checked every point
      const double c0 = c0_[static_cast<Eigen::Index>(e) * nq + q];
      const double u = -p2_.interpolate(h, el, q).dot(k.m) - c0 * k.J;
      const double w = p2_.weight(q);
      energy[e] += w * 0.5 * kb * u * u / k.J;
      moment[e] = std::max(moment[e], std::abs(kb * u / k.J));
      const Eigen::Vector3d gn = (kb * w * u / k.J) * k.m;  // κ_b w u n
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) out[3 * a + c] += p2_[q].n[a] * gn[c];
    }
  }
  for (int e = 0; e < ne; ++e) {
    s.energy += energy[e];
    s.max_moment = std::max(s.max_moment, moment[e]);
  }
  // Phase 3: the adjoint field, M Λ = G.
  Eigen::Matrix3Xd lambda;
  solver.solve(scatter(mesh_, g), lambda);

  // Phase 4: R_b = ∂/∂x [W_b(x, h) + ∫ Λ·h dS + ∫ ∇sΛ : ∇s x dS] at fixed nodal h, Λ; per point, the
  // derivatives with respect to the tangents g1, g2, then R_a += ∂ξφ_a ∂/∂g1 + ∂ηφ_a ∂/∂g2.
  std::vector<double> force(static_cast<std::size_t>(ne) * 18, 0.0);
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    const auto& el = mesh_.elements[e];
    double* out = force.data() + static_cast<std::size_t>(e) * 18;
    for (int q = 0; q < nq; ++q) {
      PointGeometry k;
      (void)point_geometry(p2_, x, el, q, k);
      const mesh::P2Point& p = p2_[q];
      const double w = p.w, J = k.J;
      const double c0 = c0_[static_cast<Eigen::Index>(e) * nq + q];
      const Eigen::Vector3d hq = p2_.interpolate(h, el, q), lq = p2_.interpolate(lambda, el, q);
      Eigen::Vector3d L1 = Eigen::Vector3d::Zero(), L2 = Eigen::Vector3d::Zero();  // ∂ξΛ, ∂ηΛ
      for (int a = 0; a < 6; ++a) {
        L1 += p.dxi[a] * lambda.col(el[a]);
        L2 += p.deta[a] * lambda.col(el[a]);
      }
      // W_b term: f = (κ_b/2) u²/J, ∂u/∂g1 = −g2 × h − c0 ∂J/∂g1, ∂u/∂g2 = −h × g1 − c0 ∂J/∂g2.
      const double u = -hq.dot(k.m) - c0 * J;
      const Eigen::Vector3d du1 = -k.g2.cross(hq) - c0 * k.dJ1, du2 = -hq.cross(k.g1) - c0 * k.dJ2;
      Eigen::Vector3d d1 = (0.5 * kb) * (2.0 * u / J * du1 - u * u / (J * J) * k.dJ1);
      Eigen::Vector3d d2 = (0.5 * kb) * (2.0 * u / J * du2 - u * u / (J * J) * k.dJ2);
      // ∫ Λ·h dS term: (Λ·h) ∂J/∂g.
      const double lh = lq.dot(hq);
      d1 += lh * k.dJ1;
      d2 += lh * k.dJ2;
      // ∫ ∇sΛ : ∇s x dS term: N/J with N = g22 P11 − g12 (P12 + P21) + g11 P22, P_αβ = ∂αΛ · g_β.
      const double P11 = L1.dot(k.g1), P12 = L1.dot(k.g2), P21 = L2.dot(k.g1), P22 = L2.dot(k.g2);
      const double N = k.g22 * P11 - k.g12 * (P12 + P21) + k.g11 * P22;
      const Eigen::Vector3d dN1 = k.g22 * L1 - (P12 + P21) * k.g2 - k.g12 * L2 + (2.0 * P22) * k.g1;
      const Eigen::Vector3d dN2 = (2.0 * P11) * k.g2 - (P12 + P21) * k.g1 - k.g12 * L1 + k.g11 * L2;
      d1 += dN1 / J - N / (J * J) * k.dJ1;
      d2 += dN2 / J - N / (J * J) * k.dJ2;
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) out[3 * a + c] += w * (p.dxi[a] * d1[c] + p.deta[a] * d2[c]);
    }
  }
  s.internal_force = scatter(mesh_, force);
  return s;
}

}  // namespace capsim::membrane
