#pragma once
/// @file
/// @brief Hyperelastic membrane laws (MFEM-style model classes). A law gives the strain energy per unit
/// undeformed area ws(I1, Js) in units of Gs, with I1 = λ1² + λ2² − 2 and Js = λ1 λ2, and its partial
/// derivatives; the Cauchy tensions per unit deformed length follow from them for every law alike:
///   τ1 = (1/λ2) ∂ws/∂λ1 = 2 (∂ws/∂I1) λ1/λ2 + ∂ws/∂Js,   τ2 = 2 (∂ws/∂I1) λ2/λ1 + ∂ws/∂Js.

#include <array>
#include <memory>
#include <string>

#include "solver/config/case_enums.h"

namespace capsim::membrane {

/// @brief Partial derivatives of ws with respect to I1 (at fixed Js) and Js (at fixed I1).
struct EnergyDerivatives {
  double d_I1 = 0.0;
  double d_Js = 0.0;
};

/// @brief Interface of a membrane constitutive law (isotropic, two-dimensional, hyperelastic).
class MembraneLaw {
 public:
  virtual ~MembraneLaw() = default;
  /// @brief Name as used in case files ("neo-hookean", "skalak").
  [[nodiscard]] virtual std::string name() const = 0;
  /// @brief ws(I1, Js) / Gs.
  [[nodiscard]] virtual double energy(double I1, double Js) const = 0;
  /// @brief (∂ws/∂I1, ∂ws/∂Js) / Gs.
  [[nodiscard]] virtual EnergyDerivatives derivatives(double I1, double Js) const = 0;
  /// @brief Principal Cauchy tensions (τ1, τ2) / Gs for principal stretches (λ1, λ2).
  [[nodiscard]] std::array<double, 2> tensions(double lambda1, double lambda2) const;
  /// @brief Area-dilation modulus Ks / Gs (small-strain limit).
  [[nodiscard]] virtual double area_dilation_modulus() const = 0;
};

/// @brief neo-Hookean membrane (thin sheet of an incompressible 3-D neo-Hookean solid):
///   ws = Gs/2 (I1 − 1 + 1/(I2 + 1)),  I2 = Js² − 1;
///   τ1 = Gs/(λ1λ2) (λ1² − 1/(λ1λ2)²).  Ks = 3 Gs. Strain-softening under large stretch.
class NeoHookeanLaw final : public MembraneLaw {
 public:
  [[nodiscard]] std::string name() const override {
    return std::string(config::word_of(config::MembraneLawKind::NeoHookean));
  }
  [[nodiscard]] double energy(double I1, double Js) const override;
  [[nodiscard]] EnergyDerivatives derivatives(double I1, double Js) const override;
  [[nodiscard]] double area_dilation_modulus() const override { return 3.0; }
};

/// @brief Skalak et al. (1973) membrane law:
///   ws = Gs/4 (I1² + 2 I1 − 2 I2 + C I2²),  C > −1/2;
///   τ1 = Gs/(λ1λ2) (λ1² (λ1² − 1) + C Js² (Js² − 1)).  Ks = Gs (1 + 2C). Strain-hardening.
class SkalakLaw final : public MembraneLaw {
 public:
  /// @throws std::invalid_argument unless C > −1/2 (finite).
  explicit SkalakLaw(double C);
  [[nodiscard]] std::string name() const override { return std::string(config::word_of(config::MembraneLawKind::Skalak)); }
  [[nodiscard]] double energy(double I1, double Js) const override;
  [[nodiscard]] EnergyDerivatives derivatives(double I1, double Js) const override;
  [[nodiscard]] double area_dilation_modulus() const override { return 1.0 + 2.0 * C_; }
  [[nodiscard]] double C() const { return C_; }

 private:
  double C_;
};

/// @brief The law of capsule.law; skalak_C is used by Skalak only.
/// @throws std::invalid_argument from SkalakLaw for C ≤ −1/2.
std::unique_ptr<MembraneLaw> make_law(config::MembraneLawKind law, double skalak_C);

}  // namespace capsim::membrane
