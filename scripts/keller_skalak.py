"""Keller & Skalak (JFM 120, 27-47, 1982): when a capsule of fixed ellipsoidal shape stops tank-treading and tumbles.

The model: an ellipsoid with semi-axes a1, a2 in the shear plane and a3 along the vorticity keeps its shape; its
membrane is a fluid (no elasticity, no memory of a rest shape) that tank-treads around the inner liquid (viscosity
λ μ) inside the outer one (μ). In capsim's convention (solver/README.md: v∞ = γ̇ (x2, 0, 0), vorticity −γ̇ e3; θ is
the angle of the a1 axis from x1 toward x2, so a tumbling capsule's θ decreases), in units of 1/γ̇:

    dθ/dt = A + B cos 2θ,    A = −1/2,
    B = (a1² − a2²) / (2 (a1² + a2²)) − 2 a1 a2 / (a1² + a2²) · ν̂          (the particle is torque-free)
    ν = ν̂ γ̇ cos 2θ,    ν̂ = −f3 / (f2 − λ f1)                               (energy balance, below)

where, in the particle's frame, the membrane moves with u = ν (−(a1/a2) x2', (a2/a1) x1', 0) (tangent to the
ellipsoid; ν < 0 turns it with the flow), and with α_i = a_i / (a1 a2 a3)^(1/3):

    z1 = (a1/a2 − a2/a1) / 2,    z2 = g3' (α1² + α2²),
    f1 = 4 z1²,    f2 = 4 z1² (1 − 2/z2),    f3 = −4 z1 / z2,
    g3' = ∫_0^∞ ds / ((α1² + s) (α2² + s) Δ(s)),    Δ(s) = sqrt((α1² + s) (α2² + s) (α3² + s)).

The torque balance is Jeffery's torque on an ellipsoid whose surface moves with the linear field of its rotation
plus the tank-treading. The energy balance equates the work of the outer liquid on the membrane with the
dissipation of the inner liquid, whose flow is the linear field u, of strain ν (a2/a1 − a1/a2)/2: hence f1 ∝
(a1/a2 − a2/a1)², which vanishes for a circular section (there tank-treading is a rigid rotation).

If |A| > |B|, dθ/dt never vanishes and the particle tumbles (period 2π / sqrt(A² − B²)); otherwise θ settles where
cos 2θ = −A/B = 1/(2B). |B| decreases as λ grows, toward Jeffery's rigid |a1² − a2²| / (2 (a1² + a2²)) < 1/2,
and |B| = 1/2 at

    λ_c = 1 + 2 / (g3' |α1² − α2²|):

above λ_c the fixed shape tumbles at every shear rate. There is no capillary number in the model (the membrane has
no elasticity), so in a (Ca, λ) plane λ_c is a horizontal line.

Sources, and how they were made to agree (the equations of the papers themselves were not readable here: the stored
pages of Keller & Skalak 1982, Abkarian, Faivre & Viallat PRL 98, 188302 (2007), Noguchi PRE 80, 021902 (2009) and
Vlahovska et al. (arXiv 1007.0444) hold their abstracts and introductions only):

1. The Keller-Skalak equations in the notation above (z1, z2, f1-f3; after Keller & Skalak 1982 and Abkarian et al.
   2007) as coded in the public notebook danladi-boop/tchabanna-academic-portfolio, projet_GB/GB_p.ipynb
   (calculate_ks_constants and its residuals). Its z1, z2, f2, f3 and its θ equation are the ones above. Its
   f1 = (a1/a2 + a2/a1)² and ν̂ = −f3 / (f2 + λ f1) are not: that f1 would make a sphere's tank-treading dissipate,
   and with it f2 + λ f1 vanishes at a finite λ (an infinite membrane frequency); source 2 fixes f1 = 4 z1² and
   the sign of λ f1. (The notebook also puts the dimensional a1² + a2² in z2, which is right only when a1 a2 a3 = 1.)
2. Roscoe (JFM 28, 273-293, 1967), the steady tank-treading of an ellipsoid with a viscous interior, eqs. (41), (43)
   and (80) as coded in fabrylab/shear_flow_deformation_cytometer (shear_flow_deformation_cytometer/includes/
   RoscoeCoreInclude.py and deformationcytometer/includes/form_factors.py). Its tank-treading frequency (41) is the
   torque balance above at dθ/dt = 0, and its angle (80),

       cos 2θ = (α1² − α2²)/(α1² + α2²) · (1 + t b²/K) / (1 + t c²/K),    t = (2/5) (λ − 1),
       K = (α1² + α2²) / (5 g3' α1² α2²),  b = (α1² + α2²) / (2 α1 α2),  c = (α1² − α2²) / (2 α1 α2),

   is cos 2θ = 1/(2B) for every shape and λ (tests/scripts/keller_skalak_check.py compares them); its cos 2θ = 1
   gives the λ_c above.
"""

import math

import numpy as np

# ∫_0^∞ F(s) ds = ∫ F(e^t) e^t dt by the trapezoidal rule: the integrand decays exponentially at both ends of t, so
# the rule converges geometrically (about 1e-12 relative with this step for spheroids of aspect ratio 0.03 to 30:
# tests/scripts/keller_skalak_check.py compares it with their closed form).
_T_STEP = 0.005
_T_BELOW = 60.0  # e^-60: the lower end's share of the integral is that small
_T_ABOVE = 40.0  # the integrand falls as e^(-5t/2) beyond the largest axis


def g3_prime(a1, a2, a3):
    """g3' = ∫_0^∞ ds / ((α1² + s)(α2² + s) Δ(s)), Δ² = (α1² + s)(α2² + s)(α3² + s), α_i = a_i / (a1 a2 a3)^(1/3)."""
    v = (a1 * a2 * a3) ** (1.0 / 3.0)
    q1, q2, q3 = (a1 / v) ** 2, (a2 / v) ** 2, (a3 / v) ** 2
    top = math.log(max(q1, q2, q3))
    t = np.arange(-_T_BELOW, top + _T_ABOVE, _T_STEP)
    s = np.exp(t)
    f = s / ((q1 + s) * (q2 + s) * np.sqrt((q1 + s) * (q2 + s) * (q3 + s)))
    return float(np.sum(f) * _T_STEP)


def coefficients(a1, a2, a3, lam):
    """(A, B, ν̂) of dθ/dt = A + B cos 2θ and ν = ν̂ γ̇ cos 2θ (module docstring), in units of γ̇.

    For a circular section (a1 = a2) the membrane turns as a rigid body with the flow: B and ν̂ are infinite."""
    if a1 == a2:
        return -0.5, math.inf, -math.inf
    v = (a1 * a2 * a3) ** (1.0 / 3.0)
    al1, al2 = a1 / v, a2 / v
    z1 = 0.5 * (a1 / a2 - a2 / a1)
    z2 = g3_prime(a1, a2, a3) * (al1 ** 2 + al2 ** 2)
    f1 = 4.0 * z1 ** 2
    f2 = 4.0 * z1 ** 2 * (1.0 - 2.0 / z2)
    f3 = -4.0 * z1 / z2
    nu_hat = -f3 / (f2 - lam * f1)
    s = a1 ** 2 + a2 ** 2
    b = (a1 ** 2 - a2 ** 2) / (2.0 * s) - 2.0 * a1 * a2 / s * nu_hat
    return -0.5, b, nu_hat


def tumbles(a1, a2, a3, lam):
    """|A| > |B|: the fixed shape tumbles (θ turns through full rotations) at every shear rate."""
    a, b, _ = coefficients(a1, a2, a3, lam)
    return abs(a) > abs(b)


def critical_viscosity_ratio(a1, a2, a3):
    """λ_c = 1 + 2 / (g3' |α1² − α2²|): tank-treading below, tumbling above (infinite for a circular section)."""
    if a1 == a2:
        return math.inf
    v = (a1 * a2 * a3) ** (1.0 / 3.0)
    return 1.0 + 2.0 / (g3_prime(a1, a2, a3) * abs((a1 / v) ** 2 - (a2 / v) ** 2))


def spheroid_in_shear_plane(aspect_ratio):
    """The semi-axes (a1, a2, a3) of the seed's capsule, in units of b: a spheroid with semi-axis a along its
    revolution axis x1 (in the shear plane) and b along x2 and x3 (solver/README.md), so (a/b, 1, 1) for the prolate
    (a/b > 1) and the oblate (a/b < 1) one alike."""
    return float(aspect_ratio), 1.0, 1.0


def critical_viscosity_ratio_of_spheroid(aspect_ratio):
    """λ_c of the seed's capsule of aspect ratio a/b at rest (infinite for the sphere)."""
    return critical_viscosity_ratio(*spheroid_in_shear_plane(aspect_ratio))
