#include "solver/membrane/membrane_law.h"

#include <cmath>

#include <gtest/gtest.h>

namespace capsim::membrane {
namespace {

// The generic tension formula τ1 = (1/λ2) ∂ws/∂λ1 must reproduce the closed forms written in the headers.
TEST(MembraneLaw, TensionsMatchClosedForms) {
  const NeoHookeanLaw nh;
  const SkalakLaw sk(1.0), sk5(5.0);
  for (double l1 : {0.6, 0.9, 1.0, 1.3, 2.0})
    for (double l2 : {0.7, 1.0, 1.1, 1.8}) {
      const double J = l1 * l2;
      const auto t = nh.tensions(l1, l2);
      EXPECT_NEAR(t[0], (l1 * l1 - 1.0 / (J * J)) / J, 1e-13);
      EXPECT_NEAR(t[1], (l2 * l2 - 1.0 / (J * J)) / J, 1e-13);
      for (const SkalakLaw* law : {&sk, &sk5}) {
        const double C = law->C();
        const auto s = law->tensions(l1, l2);
        EXPECT_NEAR(s[0], (l1 * l1 * (l1 * l1 - 1.0) + C * J * J * (J * J - 1.0)) / J, 1e-12);
        EXPECT_NEAR(s[1], (l2 * l2 * (l2 * l2 - 1.0) + C * J * J * (J * J - 1.0)) / J, 1e-12);
      }
    }
}

// The derivatives are those of the energy (central differences in I1 and Js).
TEST(MembraneLaw, DerivativesMatchEnergy) {
  const NeoHookeanLaw nh;
  const SkalakLaw sk(0.7);
  for (const MembraneLaw* law : {static_cast<const MembraneLaw*>(&nh), static_cast<const MembraneLaw*>(&sk)})
    for (double I1 : {-0.2, 0.0, 0.5, 2.0})
      for (double J : {0.8, 1.0, 1.4}) {
        const double h = 1e-6;
        const auto d = law->derivatives(I1, J);
        EXPECT_NEAR(d.d_I1, (law->energy(I1 + h, J) - law->energy(I1 - h, J)) / (2 * h), 1e-8);
        EXPECT_NEAR(d.d_Js, (law->energy(I1, J + h) - law->energy(I1, J - h)) / (2 * h), 1e-8);
      }
}

TEST(MembraneLaw, StressFreeReference) {
  EXPECT_NEAR(NeoHookeanLaw().tensions(1.0, 1.0)[0], 0.0, 1e-15);
  EXPECT_NEAR(SkalakLaw(1.0).tensions(1.0, 1.0)[1], 0.0, 1e-15);
  EXPECT_NEAR(NeoHookeanLaw().energy(0.0, 1.0), 0.0, 1e-15);
  EXPECT_NEAR(SkalakLaw(1.0).energy(0.0, 1.0), 0.0, 1e-15);
}

// neo-Hookean and Skalak C = 1 have the same small-strain behaviour (Gs, Ks = 3 Gs): their tensions differ
// at second order in the strain only.
TEST(MembraneLaw, NeoHookeanAndSkalakC1AgreeToFirstOrder) {
  const NeoHookeanLaw nh;
  const SkalakLaw sk(1.0);
  EXPECT_DOUBLE_EQ(nh.area_dilation_modulus(), sk.area_dilation_modulus());
  for (auto dir : {std::array<double, 2>{1.0, 0.0}, {1.0, 1.0}, {1.0, -0.5}, {0.3, 1.0}}) {
    double prev = 0.0;
    for (double eps : {1e-2, 5e-3, 2.5e-3}) {
      const double l1 = 1.0 + eps * dir[0], l2 = 1.0 + eps * dir[1];
      const auto a = nh.tensions(l1, l2), b = sk.tensions(l1, l2);
      const double diff = std::max(std::abs(a[0] - b[0]), std::abs(a[1] - b[1]));
      const double first_order = std::max(std::abs(a[0]), std::abs(a[1]));
      EXPECT_LT(diff, 20.0 * eps * first_order);
      if (prev > 0.0) {
        EXPECT_NEAR(prev / diff, 4.0, 0.3) << "difference must be quadratic in the strain";
      }
      prev = diff;
    }
  }
}

TEST(MembraneLaw, BadParametersThrow) {
  EXPECT_THROW(SkalakLaw(-0.5), std::invalid_argument);
  EXPECT_THROW(SkalakLaw(-1.0), std::invalid_argument);
  EXPECT_THROW(SkalakLaw(std::nan("")), std::invalid_argument);
  EXPECT_THROW(make_law(config::MembraneLawKind::Skalak, -0.5), std::invalid_argument);
  EXPECT_NO_THROW(SkalakLaw(-0.49));
  EXPECT_EQ(make_law(config::MembraneLawKind::NeoHookean, 1.0)->name(), "neo-hookean");
  EXPECT_EQ(make_law(config::MembraneLawKind::Skalak, 2.0)->name(), "skalak");
}

}  // namespace
}  // namespace capsim::membrane
