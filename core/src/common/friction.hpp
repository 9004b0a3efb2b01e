// Coulomb friction as the contacts apply it after each substep's solve (Macklin et al. 2014): the
// tangential slip of a contact point is removed up to the friction coefficient times the normal
// push, both lengths over the substep. One rule for collider, face and self contacts.
#pragma once

#include "embra/core/world.hpp"

#include <algorithm>
#include <cmath>

namespace embra {

/// The fraction (0..1) of a tangential slip of length `slip` to remove, for a normal push of length
/// `push` over a substep of `h` seconds. The coefficient falls from mu_s at rest to mu_k with the
/// slip speed, continuously (mu = mu_k + (mu_s - mu_k) exp(-v / kFrictionStribeckSpeed), v =
/// slip / h): a slip below mu push is removed whole (sticking), a larger one by mu push. A step
/// from mu_s to mu_k at the onset of sliding makes a contact on the edge of sticking stick and slip
/// in turn from substep to substep, a chatter that keeps a resting structure moving.
inline double friction_fraction(double slip, double push, double mu_s, double mu_k, double h) {
  if (!(slip > 0.0) || !(push > 0.0)) return 0.0;
  const double mu = mu_k + (mu_s - mu_k) * std::exp(-slip / (kFrictionStribeckSpeed * h));
  return std::min(mu * push / slip, 1.0);
}

}  // namespace embra
