#pragma once
/// @file
/// @brief The membrane's spin: its rotation about the material axis (solver/README.md §1b, §5), accumulated step
/// by step as the turn of one material point about the axis, with the axis's own turn transported out.
///
/// Definition. At a state x let p be the material axis (the unit vector from mesh.pole_node[1] to
/// mesh.pole_node[0], diagnostics::material_axis), m = ½ (x_pole0 + x_pole1) the midpoint of the two poles and
/// s = mesh.equator_node, the node that started on the equator at +x2 of the unrotated spheroid. Its radial
/// direction is the unit projection of x_s − m perpendicular to p:
///   u = (r − (r·p) p) / |r − (r·p) p|,  r = x_s − m.
/// From one state (p, u) to the next (p′, u′) the membrane turns about the axis by
///   δ = atan2(p′ · (T u × u′), T u · u′) ∈ (−π, π],
/// where T is the smallest rotation taking p to p′ (about p × p′, by the angle between them; Rodrigues:
/// T v = v + c × v + c × (c × v)/(1 + p·p′), c = p × p′). The spin is the running sum
///   spin(t_0) = 0,  spin(t_{n+1}) = spin(t_n) + δ_n,
/// over every time step (not only the sampled ones), in radians, positive counter-clockwise about p (right-hand
/// rule). It is unwrapped by construction: a membrane that tank-treads k times about its axis has spin ≈ ±2πk.
///
/// Why this transport. The radial direction u lives in the plane perpendicular to p, which turns with the axis;
/// comparing u with u′ needs a rule that carries one plane onto the other. T is that rule with no turn about the
/// axis of its own (parallel transport along the arc of p on the unit sphere), so:
/// - it uses no fixed frame: no reference vector that the axis could pass through, the same answer in any
///   coordinates;
/// - a rigid rotation by α about p gives δ = α exactly (for |α| < π), and a rigid rotation about any axis
///   perpendicular to p gives δ = 0 exactly (T is then that rotation, so T u = u′);
/// - for a rigid body turning at angular velocity ω the spin rate tends, as the step shrinks, to ω · p, the
///   component of ω along the axis (the transport's angular velocity is p × ṗ = ω − (ω·p) p, the rest of ω turns
///   u about p): the body's twist about its own axis, with no angle of a fixed frame that could become singular
///   when the axis crosses a coordinate direction. A rigid spheroid with its axis along the vorticity x3
///   (ω = −½ γ̇ e3 for v∞ = (γ̇ x2, 0, 0)) spins at −½ γ̇.
/// For a deforming membrane the spin is the turn of one material point: over one revolution of a membrane
/// tank-treading about a fixed axis (rolling) it is exactly 2π, while within a revolution its rate follows the
/// point along the non-circular section, so rates are best read as means over whole revolutions or long windows.
///
/// Degenerate cases give NaN, and once NaN the running sum stays NaN (the turn through a step that could not be
/// measured is lost, and a later value would be wrong by it): a mesh without pole or equator nodes; poles that
/// coincide; the equator node within 1e-8 |r| of the axis (u undefined or ill-conditioned); an axis that
/// reverses in one step (p · p′ ≤ −1 + 1e-12, where T is undefined; no physical step turns the axis by 180°).

#include <limits>

#include <Eigen/Core>

#include "solver/diagnostics/time_series.h"
#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {

/// @brief The spin's frame at one state: the material axis p and the radial direction u of the equator node
/// (file comment). Both NaN when undefined.
struct SpinFrame {
  Eigen::Vector3d axis = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d radial = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// @brief True when both vectors are defined.
  [[nodiscard]] bool valid() const { return axis.allFinite() && radial.allFinite(); }
};

/// @brief The spin frame of positions x (mesh.pole_node, mesh.equator_node).
/// @throws std::invalid_argument if x does not have one column per node.
SpinFrame spin_frame(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x);

/// @brief The turn δ ∈ (−π, π] of the membrane about its axis from frame @p from to frame @p to (file comment);
/// NaN if either frame is undefined or the axis reversed.
double spin_increment(const SpinFrame& from, const SpinFrame& to);

/// @brief The spin after a step: @p spin (that of x_from) plus the turn from x_from to x_to.
double advance_spin(double spin, const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x_from,
                    const Eigen::Matrix3Xd& x_to);

/// @brief The mean spin rate over [t_begin, t_end] (summary final_spin_rate, radians per 1/γ̇, i.e. units of γ̇):
///   (spin(t_end) − spin(t_begin)) / (t_end − t_begin),
/// spin linear between samples, the window clipped to the series. NaN when the clipped window is empty (no period
/// found) or a spin sample in it is NaN.
double final_spin_rate(const TimeSeries& series, double t_begin, double t_end);

}  // namespace capsim::diagnostics
