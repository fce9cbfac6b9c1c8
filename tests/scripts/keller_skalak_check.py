#!/usr/bin/python3
"""Checks of scripts/keller_skalak.py (the fixed-shape Keller-Skalak threshold drawn in figure 7) against physics and
against an independent theory, never against its own numbers:

- λ → ∞ (a rigid membrane cannot tank-tread) gives Jeffery's rotation of a spheroid,
  dθ/dt = −1/2 + (r² − 1)/(2 (r² + 1)) cos 2θ with θ decreasing (capsim's v∞ = (x2, 0, 0) turns clockwise), and its period 2π (r + 1/r);
- a sphere never tumbles: λ_c grows without bound as the shape tends to one, as ε (λ_c − 1) → 5/2 for a1 = 1 + ε,
  a2 = a3 = 1 (from the sphere's g3' = ∫ (1 + s)^(-7/2) ds = 2/5);
- Roscoe's (1967) steady tank-treading of a viscous ellipsoid, eqs. (41), (43), (80), coded here from their own form
  with their own integral (a closed form for spheroids, a different quadrature otherwise): its angle and membrane
  frequency are the stationary ones of the model for every shape and λ below λ_c, and its cos 2θ = 1 is λ_c;
- at λ = 1 the outer flow's integral drops out: cos 2θ = (a1² − a2²)/(a1² + a2²) whatever a3;
- the integral's quadrature against the closed form of a spheroid's.

Run: /usr/bin/python3 tests/scripts/keller_skalak_check.py (exit 0 when every check holds). tests/scripts/
keller_skalak_test.cc runs it in the default test suite.
"""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "scripts"))
import keller_skalak as ks  # noqa: E402

# Triaxial and spheroidal shapes (a1, a2 in the shear plane, a3 along the vorticity), both a1 > a2 and a1 < a2.
SHAPES = [(2.0, 1.0, 1.0), (0.5, 1.0, 1.0), (3.0, 1.0, 0.4), (1.2, 1.0, 0.8), (1.0, 0.5, 2.0), (4.0, 1.5, 1.5),
          (0.7, 1.3, 0.9)]


def spheroid_integral(a, b):
    """∫_0^∞ ds / ((a² + s)^(3/2) (b² + s)²): g3' of the ellipsoid (a, b, b) before normalisation, in closed form
    (u = sqrt(a² + s), partial fractions in u²; arctanh for a > b, arctan for a < b)."""
    if a > b:
        c = math.sqrt(a * a - b * b)
        log_term = math.log((a + c) / (a - c)) / c
    else:
        c = math.sqrt(b * b - a * a)
        log_term = 2.0 * math.atan(c / a) / c
    c4 = (a * a - b * b) ** 2
    return 2.0 / (c4 * a) + a / (c4 * b * b) - 1.5 * log_term / c4


def g3_prime_gauss(a1, a2, a3, n=400):
    """g3' by Gauss-Legendre in u, s = m² (1/u² − 1) (not the module's rule): for moderate aspect ratios only."""
    v = (a1 * a2 * a3) ** (1.0 / 3.0)
    q1, q2, q3 = (a1 / v) ** 2, (a2 / v) ** 2, (a3 / v) ** 2
    m2 = (q1 + q2 + q3) / 3.0
    x, w = np.polynomial.legendre.leggauss(n)
    u, w = 0.5 * (x + 1.0), 0.5 * w
    s = m2 * (1.0 / u ** 2 - 1.0)
    f = 1.0 / ((q1 + s) * (q2 + s) * np.sqrt((q1 + s) * (q2 + s) * (q3 + s)))
    return float(np.sum(w * f * 2.0 * m2 / u ** 3))


def roscoe(a1, a2, a3, lam):
    """Roscoe (JFM 28, 1967): (cos 2θ of eq. (80), ν/γ̇ of eq. (41) at that θ, λ_c where eq. (80) reaches 1), with
    α_i normalised to α1 α2 α3 = 1 (his eq. (28)) and the viscosity contrast entering as t = (2/5)(λ − 1) (his eq. (62):
    (τ − σ)/σ with σ = 5 η0 / (2 μ1), τ = (3 η0 + 2 η1) / (2 μ1))."""
    v = (a1 * a2 * a3) ** (1.0 / 3.0)
    x1, x2 = (a1 / v) ** 2, (a2 / v) ** 2
    g3p = g3_prime_gauss(a1, a2, a3)
    k = (x1 + x2) / (5.0 * g3p * x1 * x2)  # eq. (43)
    b = (x1 + x2) / (2.0 * math.sqrt(x1 * x2))
    c = (x1 - x2) / (2.0 * math.sqrt(x1 * x2))
    t = 0.4 * (lam - 1.0)
    cos2 = (x1 - x2) / (x1 + x2) * (1.0 + t / k * b * b) / (1.0 + t / k * c * c)  # eq. (80)
    nu = -b * (1.0 - (x1 - x2) / (x1 + x2) * cos2) / 2.0  # eq. (41), shear rate 1
    lam_c = 1.0 + 2.5 * k / (b * abs(c))  # cos 2θ = 1 in eq. (80): t = K / (b c)
    return cos2, nu, lam_c


class Quadrature(unittest.TestCase):
    def test_g3_prime_is_the_closed_form_for_spheroids(self):
        for r in (1 / 30, 0.1, 0.5, 0.8, 1.25, 2.0, 10.0, 30.0):
            v = r ** (1.0 / 3.0)  # (a1 a2 a3)^(1/3) of (r, 1, 1): the integral scales as length^-5
            exact = spheroid_integral(r, 1.0) * v ** 5
            self.assertAlmostEqual(ks.g3_prime(r, 1.0, 1.0) / exact, 1.0, delta=1e-10, msg=f"a/b = {r}")

    def test_g3_prime_is_another_quadratures_for_triaxial_shapes(self):
        for a in SHAPES:
            self.assertAlmostEqual(ks.g3_prime(*a) / g3_prime_gauss(*a), 1.0, delta=1e-10, msg=str(a))

    def test_g3_prime_is_symmetric_in_the_shear_plane_axes_and_scale_free(self):
        for a1, a2, a3 in SHAPES:
            g = ks.g3_prime(a1, a2, a3)
            self.assertAlmostEqual(ks.g3_prime(a2, a1, a3) / g, 1.0, delta=1e-12)
            self.assertAlmostEqual(ks.g3_prime(7 * a1, 7 * a2, 7 * a3) / g, 1.0, delta=1e-12)


class RigidLimit(unittest.TestCase):
    """λ → ∞: the membrane cannot move relative to the particle, which turns as Jeffery's rigid spheroid."""

    def test_jeffery_rotation_of_a_spheroid(self):
        for r in (0.25, 0.5, 2.0, 5.0):
            a, b, nu = ks.coefficients(r, 1.0, 1.0, 1e12)
            self.assertEqual(a, -0.5)
            self.assertAlmostEqual(b, (r * r - 1) / (2 * (r * r + 1)), delta=1e-10, msg=f"r = {r}")
            self.assertAlmostEqual(nu, 0.0, delta=1e-10)
            # v∞ = (x2, 0, 0) turns clockwise: θ decreases at every angle (solver/README.md), slowest along the flow
            # for a prolate body, and a full turn takes Jeffery's period 2π (r + 1/r).
            theta = np.linspace(0.0, math.pi, 181)
            self.assertTrue(np.all(a + b * np.cos(2 * theta) < 0.0))
            self.assertAlmostEqual(2 * math.pi / math.sqrt(a * a - b * b), 2 * math.pi * (r + 1 / r), delta=1e-8)

    def test_the_tank_treading_term_fades_monotonically_with_lambda(self):
        for a1, a2, a3 in SHAPES:
            jeffery = (a1 ** 2 - a2 ** 2) / (2 * (a1 ** 2 + a2 ** 2))
            gaps = [abs(ks.coefficients(a1, a2, a3, lam)[1] - jeffery) for lam in (0.0, 1.0, 10.0, 100.0, 1e4)]
            self.assertTrue(all(x > y for x, y in zip(gaps, gaps[1:])), msg=f"{(a1, a2, a3)}: {gaps}")
            self.assertTrue(ks.tumbles(a1, a2, a3, 1e6), msg=str((a1, a2, a3)))


class SphereLimit(unittest.TestCase):
    """A sphere's membrane turns as a rigid body with any λ: it never tumbles, and λ_c → ∞ as the shape tends to it."""

    def test_lambda_c_diverges_as_the_sphere_is_approached(self):
        eps = [0.2, 0.05, 0.01, 0.002]
        lam_c = [ks.critical_viscosity_ratio(1 + e, 1.0, 1.0) for e in eps]
        self.assertTrue(all(x < y for x, y in zip(lam_c, lam_c[1:])), msg=str(lam_c))
        # λ_c − 1 = 2 / (g3' (α1² − α2²)) with g3' → 2/5 and α1² − α2² → 2ε: ε (λ_c − 1) → 5/2, to first order in ε.
        for e, lc in zip(eps, lam_c):
            self.assertAlmostEqual(e * (lc - 1) / 2.5, 1.0, delta=2 * e, msg=f"ε = {e}")
        self.assertFalse(ks.tumbles(1.002, 1.0, 1.0, 100.0))

    def test_a_circular_section_never_tumbles(self):
        self.assertEqual(ks.critical_viscosity_ratio(1.0, 1.0, 1.0), math.inf)
        self.assertEqual(ks.critical_viscosity_ratio(1.0, 1.0, 0.3), math.inf)
        self.assertFalse(ks.tumbles(1.0, 1.0, 1.0, 1e6))


class Roscoe1967(unittest.TestCase):
    """Roscoe's steady state is the model's stationary one (dθ/dt = 0), from a separate derivation and notation."""

    def test_stationary_angle_and_membrane_frequency(self):
        for shape in SHAPES:
            lam_c = ks.critical_viscosity_ratio(*shape)
            for lam in (0.0, 0.2, 0.5, 1.0, 2.0, 0.999 * lam_c):
                _, b, nu_hat = ks.coefficients(*shape, lam)
                cos2 = 1.0 / (2.0 * b)  # A + B cos 2θ = 0
                r_cos2, r_nu, _ = roscoe(*shape, lam)
                self.assertAlmostEqual(cos2, r_cos2, delta=1e-9, msg=f"{shape}, λ = {lam}")
                self.assertAlmostEqual(nu_hat * cos2, r_nu, delta=1e-9, msg=f"{shape}, λ = {lam}")

    def test_critical_viscosity_ratio(self):
        for shape in SHAPES:
            lam_c = ks.critical_viscosity_ratio(*shape)
            self.assertAlmostEqual(lam_c / roscoe(*shape, 1.0)[2], 1.0, delta=1e-9, msg=str(shape))
            self.assertFalse(ks.tumbles(*shape, lam_c * (1 - 1e-6)), msg=str(shape))
            self.assertTrue(ks.tumbles(*shape, lam_c * (1 + 1e-6)), msg=str(shape))

    def test_equal_viscosities_need_no_outer_integral(self):
        # t = 0 in eq. (80); in the model f2 − f1 = −8 z1² / z2 cancels the z2 of f3.
        for a1, a2, a3 in SHAPES:
            _, b, _ = ks.coefficients(a1, a2, a3, 1.0)
            self.assertAlmostEqual(1.0 / (2.0 * b), (a1 ** 2 - a2 ** 2) / (a1 ** 2 + a2 ** 2), delta=1e-12)


class SeedCapsules(unittest.TestCase):
    """The spheroids of figure 7: revolution axis (semi-axis a) along x1 in the shear plane, b along x2 and x3."""

    def test_axes_and_thresholds(self):
        for ar in (0.5, 2.0):
            self.assertEqual(ks.spheroid_in_shear_plane(ar), (ar, 1.0, 1.0))
            # The closed form, in lengths (λ_c is scale-free):
            # λ_c = 1 + 2 / (a b² |a² − b²| ∫ ds / ((a² + s)^(3/2) (b² + s)²)).
            closed = 1.0 + 2.0 / (ar * abs(ar * ar - 1.0) * spheroid_integral(ar, 1.0))
            self.assertAlmostEqual(ks.critical_viscosity_ratio_of_spheroid(ar) / closed, 1.0, delta=1e-10)
        self.assertEqual(ks.critical_viscosity_ratio_of_spheroid(1.0), math.inf)


if __name__ == "__main__":
    unittest.main(verbosity=2)
