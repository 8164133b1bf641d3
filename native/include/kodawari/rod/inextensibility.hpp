// Exact inextensibility of a chain by "fast projection" (Goldenthal, Harmon, Fattal,
// Bercovier & Grinspun 2007, "Efficient simulation of inextensible cloth"): a few Newton
// steps of the mass-weighted projection onto the constraint manifold |x_{k+1} - x_k| = l_k.
// For a chain the system J M^-1 J^T is tridiagonal, so every step is one O(n) Thomas solve
// (the same structure the direct rod solver of Deul et al. 2018 exploits).
//
// Why not "follow the leader" (moving each child onto its parent's sphere, root to tip):
// that one-sided correction does not conserve momentum, and when v = dx/dt is taken
// afterwards every correction is passed down to the tip as velocity. On chains of ten
// or more bones that pumps energy in faster than damping removes it (docs/algorithms.md
// §3.3 step 3). A mass-weighted projection moves both ends of each segment, like the PBD
// distance constraint (Müller et al. 2007) it generalises, and keeps momentum.
#pragma once

#include <cstddef>

#include "kodawari/common.hpp"

namespace kodawari::rod {

// Projects x[0..count) onto the chain's lengths (lengths[k] between x[k] and x[k + 1]).
// inverse_mass[k] = 0 marks a kinematic particle (the root). `scratch` holds at least
// 9 * count values (aligned for Vec3). True when every length is within 1e-5 (relative) on return.
bool project_chain_lengths(Vec3* x, std::size_t count, const Real* lengths, const Real* inverse_mass,
                           Real* scratch, int newton_steps = 6, int sweeps = 1);

}  // namespace kodawari::rod
