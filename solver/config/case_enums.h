#pragma once
/// @file
/// @brief The case keys whose value is one of a few words, as enums. A word is parsed once, where a case is read
/// (CaseConfig holds the enum; case_keys.cc converts between the two), and the solver switches on the enum. The
/// words are those of case files, `--set`, the case identity and the stored results: they never change.

#include <array>
#include <optional>
#include <string_view>
#include <utility>

namespace capsim::config {

/// @brief time.scheme: the time integrator (solver/dynamics/time_stepper.h).
enum class TimeScheme { Rkc, Rk2 };

/// @brief capsule.law: the membrane constitutive law (solver/membrane/membrane_law.h).
enum class MembraneLawKind { NeoHookean, Skalak };

/// @brief The words of an enum key, in the order the registry lists them (messages, schemas/case_keys.md).
template <class E>
struct KeyWords;
template <>
struct KeyWords<TimeScheme> {
  static constexpr std::array<std::pair<TimeScheme, std::string_view>, 2> words{
      {{TimeScheme::Rkc, "rkc"}, {TimeScheme::Rk2, "rk2"}}};
};
template <>
struct KeyWords<MembraneLawKind> {
  static constexpr std::array<std::pair<MembraneLawKind, std::string_view>, 2> words{
      {{MembraneLawKind::NeoHookean, "neo-hookean"}, {MembraneLawKind::Skalak, "skalak"}}};
};

/// @brief The word of @p value ("rkc", "skalak", ...).
template <class E>
constexpr std::string_view word_of(E value) {
  for (const auto& [e, w] : KeyWords<E>::words)
    if (e == value) return w;
  return {};
}

/// @brief The value named @p word, or nullopt if the key has no such word.
template <class E>
constexpr std::optional<E> from_word(std::string_view word) {
  for (const auto& [e, w] : KeyWords<E>::words)
    if (w == word) return e;
  return std::nullopt;
}

}  // namespace capsim::config
