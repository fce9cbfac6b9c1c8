#include "solver/membrane/membrane_law.h"

#include <cmath>
#include <stdexcept>

namespace capsim::membrane {

std::array<double, 2> MembraneLaw::tensions(double l1, double l2) const {
  const double I1 = l1 * l1 + l2 * l2 - 2.0;
  const EnergyDerivatives d = derivatives(I1, l1 * l2);
  return {2.0 * d.d_I1 * l1 / l2 + d.d_Js, 2.0 * d.d_I1 * l2 / l1 + d.d_Js};
}

double NeoHookeanLaw::energy(double I1, double Js) const { return 0.5 * (I1 - 1.0 + 1.0 / (Js * Js)); }

EnergyDerivatives NeoHookeanLaw::derivatives(double /*I1*/, double Js) const {
  return {0.5, -1.0 / (Js * Js * Js)};
}

SkalakLaw::SkalakLaw(double C) : C_(C) {
  if (!(C > -0.5) || !std::isfinite(C))
    throw std::invalid_argument("capsule.skalak_C = " + std::to_string(C) + " is out of range (must be > -0.5)");
}

double SkalakLaw::energy(double I1, double Js) const {
  const double I2 = Js * Js - 1.0;
  return 0.25 * (I1 * I1 + 2.0 * I1 - 2.0 * I2 + C_ * I2 * I2);
}

EnergyDerivatives SkalakLaw::derivatives(double I1, double Js) const {
  const double I2 = Js * Js - 1.0;
  // ∂ws/∂I2 = (C I2 − 1)/2 and ∂I2/∂Js = 2 Js.
  return {0.5 * (I1 + 1.0), Js * (C_ * I2 - 1.0)};
}

std::unique_ptr<MembraneLaw> make_law(config::MembraneLawKind law, double skalak_C) {
  switch (law) {
    case config::MembraneLawKind::NeoHookean: return std::make_unique<NeoHookeanLaw>();
    case config::MembraneLawKind::Skalak: return std::make_unique<SkalakLaw>(skalak_C);
  }
  throw std::invalid_argument("make_law: not a capsule.law value");
}

}  // namespace capsim::membrane
