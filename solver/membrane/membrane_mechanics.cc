#include "solver/membrane/membrane_mechanics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>


namespace capsim::membrane {
namespace {

// Kinematics of one quadrature point: current tangents, metric and its inverse.
struct PointKinematics {
  Eigen::Vector3d g1, g2;
  double g11, g12, g22, det_g;
};

}  // namespace

MembraneMechanics::MembraneMechanics(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& reference,
                                     const MembraneLaw& law, Options options)
    : mesh_(mesh), law_(law) {
  if (reference.cols() != mesh.num_nodes())
    throw std::invalid_argument("MembraneMechanics: reference has " + std::to_string(reference.cols()) +
                                " nodes, mesh has " + std::to_string(mesh.num_nodes()));
  p2_ = mesh::P2Tabulation::of_degree(options.quadrature_degree);
  const int nq = p2_.size();
  ref_.reserve(static_cast<std::size_t>(mesh.num_elements()) * nq);
  double max_area = 0.0;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const auto& el = mesh.elements[e];
    for (int q = 0; q < nq; ++q) {
      const auto [G1, G2] = p2_.tangents(reference, el, q);
      const double G11 = G1.dot(G1), G12 = G1.dot(G2), G22 = G2.dot(G2);
      const double det = G11 * G22 - G12 * G12;
      max_area = std::max(max_area, det);
      if (!(det > 0.0))
        throw std::invalid_argument("membrane: element " + std::to_string(e) + " of the reference surface is degenerate");
      ref_.push_back({{G22 / det, -G12 / det, G11 / det}, p2_.weight(q) * std::sqrt(det)});
    }
  }
  // A collapsed element relative to the others is as bad as a zero one: its metric is ill-conditioned.
  for (std::size_t i = 0; i < ref_.size(); ++i) {
    const double det = 1.0 / (ref_[i].Ginv[0] * ref_[i].Ginv[2] - ref_[i].Ginv[1] * ref_[i].Ginv[1]);
    if (det < 1e-20 * max_area)
      throw std::invalid_argument("membrane: element " + std::to_string(i / nq) +
                                  " of the reference surface is degenerate");
  }
  // The elements under the mirror, x → −x and both, for evaluate_symmetric.
  for (int g = 0; g < 3; ++g) orbits_[g] = mesh::element_orbits(mesh, g != 1, g != 0);  // mirror, x → −x, both
}

namespace {
// Kinematics of element el at point q of the tabulation; false if the element collapsed or is non-finite.
bool point_kinematics(const mesh::P2Tabulation& p2, const Eigen::Matrix3Xd& x, const std::array<int, 6>& el, int q,
                      PointKinematics& k) {
  const mesh::Tangents g = p2.tangents(x, el, q);
  k.g1 = g.g1;
  k.g2 = g.g2;
  k.g11 = k.g1.dot(k.g1);
  k.g12 = k.g1.dot(k.g2);
  k.g22 = k.g2.dot(k.g2);
  k.det_g = k.g11 * k.g22 - k.g12 * k.g12;
  return k.det_g > 0.0;
}

// Collapsed relative to the reference: an area ratio Js below 1e-10 (Js² = det g / det G). A test on
// det g > 0 alone is not enough: the tangents of an element whose six nodes coincide are Σ_a ∂N_a x0,
// zero only up to the rounding of Σ_a ∂N_a, and on some instruction sets that leaves det g ≈ 1e-32 > 0.
bool collapsed_against(const double* Ginv, const PointKinematics& k) {
  return !(k.det_g * (Ginv[0] * Ginv[2] - Ginv[1] * Ginv[1]) > 1e-20);
}

[[noreturn]] void collapsed(int e) {
  throw DegenerateSurface("membrane: element " + std::to_string(e) + " collapsed or non-finite");
}
}  // namespace

template <class Visit>
void MembraneMechanics::for_each_point(const Eigen::Matrix3Xd& x, Visit&& visit) const {
  const int nq = p2_.size();
  for (int e = 0; e < mesh_.num_elements(); ++e) {
    const auto& el = mesh_.elements[e];
    for (int q = 0; q < nq; ++q) {
      PointKinematics k;
      const RefPoint& r = ref_[static_cast<std::size_t>(e) * nq + q];
      if (!point_kinematics(p2_, x, el, q, k) || collapsed_against(r.Ginv, k)) collapsed(e);
      visit(e, q, r, k);
    }
  }
}

namespace {
struct Invariants {
  double I1, Js, l1, l2;
};
// Invariants and principal stretches from the mixed tensor C = G^{-1} g. The discriminant is formed as
// (C¹₁ − C²₂)² + 4 C¹₂ C²₁ rather than tr² − 4 det, which would cancel catastrophically near an isotropic
// state (λ1 ≈ λ2) and leave a spurious √ε ≈ 1e-8 split between the principal tensions.
template <class Ref>
Invariants invariants(const Ref& r, const PointKinematics& k) {
  const double* Gi = r.Ginv;
  const double C11 = Gi[0] * k.g11 + Gi[1] * k.g12, C12 = Gi[0] * k.g12 + Gi[1] * k.g22;
  const double C21 = Gi[1] * k.g11 + Gi[2] * k.g12, C22 = Gi[1] * k.g12 + Gi[2] * k.g22;
  const double trace = C11 + C22;
  const double J2 = k.det_g * (Gi[0] * Gi[2] - Gi[1] * Gi[1]);
  const double disc = std::sqrt(std::max(0.0, (C11 - C22) * (C11 - C22) + 4.0 * C12 * C21));
  const double l1 = std::sqrt(0.5 * (trace + disc));
  const double Js = std::sqrt(J2);
  return {trace - 2.0, Js, l1, Js / l1};
}
}  // namespace

MembraneState MembraneMechanics::evaluate(const Eigen::Matrix3Xd& x, bool with_energy) const {
  return evaluate_elements(x, with_energy, nullptr);
}

MembraneState MembraneMechanics::evaluate_centrally_symmetric(const Eigen::Matrix3Xd& x, bool with_energy) const {
  return evaluate_symmetric(x, with_energy, false, true);
}

MembraneState MembraneMechanics::evaluate_symmetric(const Eigen::Matrix3Xd& x, bool with_energy, bool mirror,
                                                    bool central) const {
  const mesh::ElementOrbits* orbits = (mirror || central) ? &orbits_[(mirror ? 1 : 0) + (central ? 2 : 0) - 1] : nullptr;
  return evaluate_elements(x, with_energy, orbits && !orbits->empty() ? orbits : nullptr);
}

MembraneState MembraneMechanics::evaluate_elements(const Eigen::Matrix3Xd& x, bool with_energy,
                                                   const mesh::ElementOrbits* orbits) const {
  // Two phases, so that the result is bitwise the same for any thread count: (1) in parallel over elements,
  // each element's forces on its six nodes, energy and tension extremes into its own slot; (2) serially in
  // element order, the sums over elements. Per-call buffers keep evaluate() const and thread-safe.
  const int ne = mesh_.num_elements(), nq = p2_.size();
  std::vector<double> force(static_cast<std::size_t>(ne) * 18), energy(static_cast<std::size_t>(ne)),
      lo(static_cast<std::size_t>(ne)), hi(static_cast<std::size_t>(ne));
  int first_collapsed = ne;
  const int count = orbits ? static_cast<int>(orbits->representatives.size()) : ne;
  const int* which = orbits ? orbits->representatives.data() : nullptr;
#pragma omp parallel for schedule(static) reduction(min : first_collapsed)
  for (int k = 0; k < count; ++k) {
    const int e = which ? which[k] : k;
    const auto& el = mesh_.elements[e];
    double fe[6][3] = {}, we = 0.0;
    double tmin = std::numeric_limits<double>::infinity(), tmax = -std::numeric_limits<double>::infinity();
    for (int q = 0; q < nq; ++q) {
      PointKinematics k;
      const RefPoint& r = ref_[static_cast<std::size_t>(e) * nq + q];
      if (!point_kinematics(p2_, x, el, q, k) || collapsed_against(r.Ginv, k)) {
        first_collapsed = std::min(first_collapsed, e);
        break;
      }
      const Invariants inv = invariants(r, k);
      if (with_energy) we += r.weight0 * law_.energy(inv.I1, inv.Js);
      const EnergyDerivatives d = law_.derivatives(inv.I1, inv.Js);
      const double tau0 = 2.0 * d.d_I1 * inv.l1 / inv.l2 + d.d_Js, tau1 = 2.0 * d.d_I1 * inv.l2 / inv.l1 + d.d_Js;
      // λ1 ≥ λ2 does not order the tensions: Skalak's τ1 − τ2 = (λ1² + λ2² − 1)(λ1/λ2 − λ2/λ1) is negative
      // under strong compression (solver/README.md §2), so both are compared.
      tmin = std::min({tmin, tau0, tau1});
      tmax = std::max({tmax, tau0, tau1});
      // A^{αβ} = 2 ws_I1 G^{αβ} + ws_J Js g^{αβ}, with g^{αβ} the inverse current metric.
      const double ginv11 = k.g22 / k.det_g, ginv12 = -k.g12 / k.det_g, ginv22 = k.g11 / k.det_g;
      const double c1 = 2.0 * d.d_I1, c2 = d.d_Js * inv.Js;
      const double A11 = c1 * r.Ginv[0] + c2 * ginv11;
      const double A12 = c1 * r.Ginv[1] + c2 * ginv12;
      const double A22 = c1 * r.Ginv[2] + c2 * ginv22;
      // R_a += w0 (A^{1β} g_β ∂N_a/∂ξ + A^{2β} g_β ∂N_a/∂η).
      const Eigen::Vector3d t1 = r.weight0 * (A11 * k.g1 + A12 * k.g2);
      const Eigen::Vector3d t2 = r.weight0 * (A12 * k.g1 + A22 * k.g2);
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) fe[a][c] += p2_[q].dxi[a] * t1[c] + p2_[q].deta[a] * t2[c];
    }
    double* out = force.data() + static_cast<std::size_t>(e) * 18;
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) out[3 * a + c] = fe[a][c];
    energy[e] = we;
    lo[e] = tmin;
    hi[e] = tmax;
  }
  if (first_collapsed < ne) collapsed(first_collapsed);  // the lowest such element, as a serial loop would
  if (orbits) {
    // The images of the evaluated elements: R is equivariant (R_g(i) = S_g R_i), so an image's forces are its
    // representative's with the group element's signs, on the image nodes; energy and tension extremes are the same.
    for (const mesh::ElementOrbits::Image& im : orbits->images) {
      const double* from = force.data() + static_cast<std::size_t>(im.from) * 18;
      double* to = force.data() + static_cast<std::size_t>(im.element) * 18;
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) to[3 * im.local[a] + c] = im.sign[c] * from[3 * a + c];
      energy[im.element] = energy[im.from];
      lo[im.element] = lo[im.from];
      hi[im.element] = hi[im.from];
    }
  }
  MembraneState s;
  s.internal_force = Eigen::Matrix3Xd::Zero(3, x.cols());
  s.tau_min = std::numeric_limits<double>::infinity();
  s.tau_max = -std::numeric_limits<double>::infinity();
  for (int e = 0; e < ne; ++e) {
    const auto& el = mesh_.elements[e];
    const double* fe = force.data() + static_cast<std::size_t>(e) * 18;
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) s.internal_force(c, el[a]) += fe[3 * a + c];
    s.energy += energy[e];  // zeros without with_energy: NaN below
    s.tau_min = std::min(s.tau_min, lo[e]);
    s.tau_max = std::max(s.tau_max, hi[e]);
  }
  if (!with_energy) s.energy = std::numeric_limits<double>::quiet_NaN();
  return s;
}

double MembraneMechanics::energy(const Eigen::Matrix3Xd& x) const {
  double w = 0.0;
  for_each_point(x, [&](int, int, const RefPoint& r, const PointKinematics& k) {
    const Invariants inv = invariants(r, k);
    w += r.weight0 * law_.energy(inv.I1, inv.Js);
  });
  return w;
}

std::vector<std::array<double, 2>> MembraneMechanics::principal_stretches(const Eigen::Matrix3Xd& x) const {
  std::vector<std::array<double, 2>> out;
  out.reserve(ref_.size());
  for_each_point(x, [&](int, int, const RefPoint& r, const PointKinematics& k) {
    const Invariants inv = invariants(r, k);
    out.push_back({inv.l1, inv.l2});
  });
  return out;
}

std::vector<std::array<double, 2>> MembraneMechanics::principal_tensions(const Eigen::Matrix3Xd& x) const {
  std::vector<std::array<double, 2>> out;
  out.reserve(ref_.size());
  for_each_point(x, [&](int, int, const RefPoint& r, const PointKinematics& k) {
    const Invariants inv = invariants(r, k);
    const auto tau = law_.tensions(inv.l1, inv.l2);  // along λ1, along λ2: not always τ1 ≥ τ2 (see evaluate)
    out.push_back({std::max(tau[0], tau[1]), std::min(tau[0], tau[1])});
  });
  return out;
}

AreaVolume area_and_volume(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, int quadrature_degree) {
  const auto p2 = mesh::P2Tabulation::of_degree(quadrature_degree);
  AreaVolume av;
  for (const auto& el : mesh.elements) {
    for (int q = 0; q < p2.size(); ++q) {
      const Eigen::Vector3d p = p2.interpolate(x, el, q);
      const auto [g1, g2] = p2.tangents(x, el, q);
      const Eigen::Vector3d n_da = g1.cross(g2);  // outward normal times the area element
      const double w = p2.weight(q);
      av.area += w * n_da.norm();
      av.volume += w * p.dot(n_da) / 3.0;
    }
  }
  return av;
}

}  // namespace capsim::membrane
