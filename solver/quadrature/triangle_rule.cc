#include "solver/quadrature/triangle_rule.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace capsim::quadrature {
namespace {

// Orbit builders: the rules are fully symmetric, so each weight comes with a class of points.
void add_centroid(TriangleRule& r, double w) {
  r.points.push_back({1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0});
  r.weights.push_back(w);
}
// (a, b, b) and its 3 permutations.
void add_orbit3(TriangleRule& r, double w, double a) {
  const double b = 0.5 * (1.0 - a);
  r.points.push_back({a, b, b});
  r.points.push_back({b, a, b});
  r.points.push_back({b, b, a});
  for (int i = 0; i < 3; ++i) r.weights.push_back(w);
}
// (a, b, c) all distinct and their 6 permutations.
void add_orbit6(TriangleRule& r, double w, double a, double b) {
  const double c = 1.0 - a - b;
  const std::array<std::array<double, 3>, 6> p = {{{a, b, c}, {a, c, b}, {b, a, c}, {b, c, a}, {c, a, b}, {c, b, a}}};
  for (const auto& x : p) {
    r.points.push_back(x);
    r.weights.push_back(w);
  }
}

// Exact ∫ ξ^i η^j over the unit right triangle, divided by its area ½.
double monomial_mean(int i, int j) {
  return 2.0 * std::tgamma(i + 1.0) * std::tgamma(j + 1.0) / std::tgamma(i + j + 3.0);
}

// A symmetric rule described by orbits: kind 1 = centroid, 3 = (a,b,b), 6 = (a,b,c); params per orbit:
// weight, then 0, 1 or 2 coordinates.
struct Orbit {
  int kind;
  double w, a, b;
};

TriangleRule build(int degree, const std::vector<Orbit>& orbits) {
  TriangleRule r;
  r.degree = degree;
  for (const auto& o : orbits) {
    if (o.kind == 1) add_centroid(r, o.w);
    if (o.kind == 3) add_orbit3(r, o.w, o.a);
    if (o.kind == 6) add_orbit6(r, o.w, o.a, o.b);
  }
  return r;
}

// The published 15-digit values are polished to full double precision by Gauss-Newton on the moment
// equations (all monomials up to the degree), so exactness holds to round-off, not to 1e-15.
TriangleRule polish(int degree, std::vector<Orbit> orbits) {
  auto unknowns = [&](std::vector<Orbit>& os) {
    std::vector<double*> u;
    for (auto& o : os) {
      u.push_back(&o.w);
      if (o.kind >= 3) u.push_back(&o.a);
      if (o.kind == 6) u.push_back(&o.b);
    }
    return u;
  };
  auto residual = [&](const std::vector<Orbit>& os) {
    const TriangleRule r = build(degree, os);
    std::vector<double> res;
    for (int i = 0; i <= degree; ++i)
      for (int j = 0; i + j <= degree; ++j) {
        double s = 0.0;
        for (int k = 0; k < r.size(); ++k) s += r.weights[k] * std::pow(r.points[k][1], i) * std::pow(r.points[k][2], j);
        res.push_back(s - monomial_mean(i, j));
      }
    return res;
  };
  for (int it = 0; it < 4; ++it) {
    const std::vector<double> r0 = residual(orbits);
    auto u = unknowns(orbits);
    const int m = static_cast<int>(r0.size()), n = static_cast<int>(u.size());
    // Normal equations J^T J du = -J^T r with a central-difference Jacobian (the residual itself is exact).
    std::vector<double> J(static_cast<std::size_t>(m) * n);
    for (int c = 0; c < n; ++c) {
      const double h = 1e-6, keep = *u[c];
      *u[c] = keep + h;
      const auto rp = residual(orbits);
      *u[c] = keep - h;
      const auto rm = residual(orbits);
      *u[c] = keep;
      for (int rI = 0; rI < m; ++rI) J[rI * n + c] = (rp[rI] - rm[rI]) / (2 * h);
    }
    std::vector<double> A(n * n, 0.0), g(n, 0.0);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b)
        for (int rI = 0; rI < m; ++rI) A[a * n + b] += J[rI * n + a] * J[rI * n + b];
      for (int rI = 0; rI < m; ++rI) g[a] -= J[rI * n + a] * r0[rI];
    }
    // Gaussian elimination with partial pivoting (n ≤ 5).
    for (int k = 0; k < n; ++k) {
      int piv = k;
      for (int rI = k + 1; rI < n; ++rI)
        if (std::abs(A[rI * n + k]) > std::abs(A[piv * n + k])) piv = rI;
      for (int c = 0; c < n; ++c) std::swap(A[k * n + c], A[piv * n + c]);
      std::swap(g[k], g[piv]);
      for (int rI = k + 1; rI < n; ++rI) {
        const double f = A[rI * n + k] / A[k * n + k];
        for (int c = k; c < n; ++c) A[rI * n + c] -= f * A[k * n + c];
        g[rI] -= f * g[k];
      }
    }
    for (int k = n - 1; k >= 0; --k) {
      double s = g[k];
      for (int c = k + 1; c < n; ++c) s -= A[k * n + c] * g[c];
      g[k] = s / A[k * n + k];
    }
    for (int c = 0; c < n; ++c) *u[c] += g[c];
  }
  return build(degree, orbits);
}

TriangleRule make_degree1() {
  // Centroid rule: exact for linear functions (the far-field tier of the boundary integral).
  return build(1, {{1, 1.0, 0.0, 0.0}});
}

TriangleRule make_degree2() {
  // Strang–Fix 3-point rule with interior points (2/3, 1/6, 1/6): exact to degree 2. The interior variant
  // (rather than the edge-midpoint one) keeps the points off the edges shared with neighbouring elements.
  return build(2, {{3, 1.0 / 3.0, 2.0 / 3.0, 0.0}});
}

TriangleRule make_degree4() {
  // Dunavant (1985), 6 points (solver/README.md §6).
  return polish(4, {{3, 0.223381589678011, 0.108103018168070, 0.0},
                    {3, 0.109951743655322, 0.816847572980459, 0.0}});
}

TriangleRule make_degree5() {
  // Radon (1948), 7 points, closed form.
  const double s = std::sqrt(15.0);
  return build(5, {{1, 9.0 / 40.0, 0.0, 0.0},
                   {3, (155.0 + s) / 1200.0, (9.0 - 2.0 * s) / 21.0, 0.0},    // a ≈ 0.0597158717
                   {3, (155.0 - s) / 1200.0, (9.0 + 2.0 * s) / 21.0, 0.0}});  // a ≈ 0.7974269853
}

TriangleRule make_degree6() {
  // Dunavant (1985), 12 points (solver/README.md §6).
  return polish(6, {{3, 0.116786275726379, 0.501426509658179, 0.0},
                    {3, 0.050844906370207, 0.873821971016996, 0.0},
                    {6, 0.082851075618374, 0.053145049844817, 0.310352451033784}});
}

}  // namespace

const TriangleRule& triangle_rule(int degree) {
  static const TriangleRule r1 = make_degree1();
  static const TriangleRule r2 = make_degree2();
  static const TriangleRule r4 = make_degree4();
  static const TriangleRule r5 = make_degree5();
  static const TriangleRule r6 = make_degree6();
  switch (degree) {
    case 1: return r1;
    case 2: return r2;
    case 4: return r4;
    case 5: return r5;
    case 6: return r6;
    default:
      throw std::invalid_argument("triangle_rule: degree " + std::to_string(degree) +
                                  " is not available (choose 1, 2, 4, 5 or 6; 1 and 2 serve the far-field tier only)");
  }
}

LineRule gauss_legendre(int n) {
  if (n < 1) throw std::invalid_argument("gauss_legendre: n must be >= 1");
  LineRule r;
  r.nodes.resize(n);
  r.weights.resize(n);
  // Newton on P_n with the Chebyshev-like initial guess; nodes mapped from [-1, 1] to [0, 1].
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      if (n == 1) { p1 = x; p0 = 1.0; }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = (n == 1) ? 1.0 : n * (x * p1 - p0) / (x * x - 1.0);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    r.nodes[i] = 0.5 * (1.0 - x);
    r.nodes[n - 1 - i] = 0.5 * (1.0 + x);
    r.weights[i] = r.weights[n - 1 - i] = 0.5 * w;
  }
  return r;
}

}  // namespace capsim::quadrature
