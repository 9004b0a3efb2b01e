// Contacts with colliders, shared by the step's stages: the gap of a contact and a collider's
// motion over the substep (contacts.cpp).
#pragma once

#include "embra/core/world.hpp"

namespace embra {

/// Signed gap of a contact's particle at `x` beyond the clearance `r` (the particle's radius plus
/// the collider's thickness), and the outward normal it is pushed along.
double contact_gap(const Collider& c, const Contact& ct, const Vec3& x, const Vec3& from, double r, Vec3& normal);

/// Position of the collider's material point now at `x`, as it was at the start of the substep.
Vec3 collider_point_before(const Collider& c, const Vec3& x);

}  // namespace embra
