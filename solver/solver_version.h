#pragma once
/// @file
/// @brief Version of the numerical results of the solver, the part of a case's identity that says "same
/// code answer". Bump it in any change that alters what `capsim run` computes (method, defaults that enter
/// the results, bug fixes in the physics); do not bump it for documentation, the campaign layer or speed-ups
/// that leave results unchanged to round-off. The exact build (git commit) is recorded separately on every
/// result as code_version, so provenance is never lost.

namespace capsim {
/// @brief Numerical-results version of the solver.
inline constexpr const char* kSolverVersion = "3";  // 2: volume correction on by default; 3: the flow
// evaluation's phases rearranged (volume flux exact by flux moments, symmetry-reduced load solve): the same method,
// results moved at round-off and CG-tolerance level (results/README.md, "Solver versions")
}  // namespace capsim
