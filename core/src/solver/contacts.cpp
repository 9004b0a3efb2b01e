// Contacts: finding them (colliders, panel faces), projecting them, friction, and settling swept
// contacts on the surface (the step's contact stages, step.cpp).
#include "solver/contacts.hpp"

#include "collision/collider_shapes.hpp"
#include "collision/self_collision.hpp"
#include "common/friction.hpp"
#include "common/pool.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace embra {

namespace {
/// Particles per thread below which the contact search is not split (a box or mesh costs a distance
/// query a particle near it; the rest a bounds test).
constexpr size_t kContactGrain = 1024;
/// Panels per thread below which the face-contact search is not split (four closest points each).
constexpr size_t kFaceGrain = 128;

/// Signed gap of a particle to a collider's surface, and the outward normal there.
double collider_gap(const Collider& c, const Vec3& x, const Vec3& from, Vec3& normal) {
  if (c.desc.shape == ColliderShape::plane) {
    normal = c.rotation * Vec3::UnitZ();
    return normal.dot(x - c.position);
  }
  const Vec3 d = x - c.position;
  const Vec3 back = from - c.position;
  // A particle that crossed the centre within the substep is pushed back out the side it came from.
  if (d.norm() < 1e-12 || d.dot(back) < 0.0) {
    normal = back.norm() > 1e-12 ? Vec3(back.normalized()) : Vec3(Vec3::UnitZ());
    return normal.dot(x - c.position) - c.desc.radius;
  }
  const double len = d.norm();
  normal = d / len;
  return len - c.desc.radius;
}

}  // namespace

/// Signed gap of a contact's particle at `x` beyond the clearance `r` (the particle's radius plus
/// the collider's thickness), and the outward normal it is pushed along.
double contact_gap(const Collider& c, const Contact& ct, const Vec3& x, const Vec3& from, double r, Vec3& normal) {
  if (!c.geometry) return collider_gap(c, x, from, normal) - r;
  const Vec3 local = c.rotation.conjugate() * (x - c.position);
  if (ct.swept) {
    normal = c.rotation * ct.normal;
    return ct.normal.dot(local) - ct.offset;
  }
  Vec3 n;
  const double d = shape_distance(c.desc, *c.geometry, local, n);
  normal = c.rotation * n;
  return d - r;
}

/// Position of the collider's material point now at `x`, as it was at the start of the substep.
Vec3 collider_point_before(const Collider& c, const Vec3& x) {
  const Vec3 local = c.rotation.conjugate() * (x - c.position);
  return c.position_prev + c.rotation_prev * local;
}

void World::find_contacts() {
  Group& g = groups_[settings_.contact_group.index];
  g.contacts.clear();
  for (size_t c = 0; c < colliders_.size(); ++c)
    if (colliders_[c].alive) find_collider_contacts(static_cast<int32_t>(c), nullptr, g.contacts);
  if (!colliders_.empty()) detected_ = x_;
}

void World::find_collider_contacts(int32_t index, const std::vector<int32_t>* only, std::vector<Contact>& out) {
  // Each part looks at a contiguous run of the particles: the contacts stand in particle order.
  pool_->collect(0, only ? only->size() : x_.size(), kContactGrain, contact_parts_, out,
                 [&](size_t begin, size_t end, std::vector<Contact>& part) {
                   find_collider_contacts(index, only, begin, end, part);
                 });
}

void World::find_collider_contacts(int32_t index, const std::vector<int32_t>* only, size_t begin, size_t end,
                                   std::vector<Contact>& out) const {
  const Collider& col = colliders_[index];
  if (col.geometry) {
    find_shape_contacts(index, only, begin, end, out);
    return;
  }
  const Vec3 normal = col.rotation * Vec3::UnitZ();
  for (size_t k = begin; k < end; ++k) {
    const size_t i = only ? static_cast<size_t>((*only)[k]) : k;
    if (w_[i] == 0.0) continue;
    // The clearance, plus the path, plus the clearance again as a margin (see find_shape_contacts).
    const Vec3 d = x_[i] - x_prev_[i];
    const double clearance2 = 2.0 * (radius_[i] + col.desc.thickness);
    if (col.desc.shape == ColliderShape::sphere) {
      // The closest point of the swept segment to the sphere's centre (below) catches a particle that
      // crosses the whole sphere within one substep. No point of the segment is nearer the centre
      // than its start less the path: a start beyond the radius, the reach and the path (by far more
      // than rounding) has no contact, found without the division and the roots below; the path
      // is bounded by the sum of its coordinates' magnitudes first (a weaker test, its margin
      // doubled for the bound's own rounding).
      const double longer = d.cwiseAbs().sum();
      const double beyond = col.desc.radius + clearance2 + 2.0 * longer;
      if ((x_prev_[i] - col.position).squaredNorm() > beyond * beyond * (1.0 + 2e-9)) continue;
    }
    const double path = d.norm();
    const double reach = clearance2 + path;
    double gap;
    if (col.desc.shape == ColliderShape::plane) {
      gap = normal.dot(x_[i] - col.position);
    } else {
      const Vec3 a = x_prev_[i];
      const double beyond = col.desc.radius + reach + path;
      if ((a - col.position).squaredNorm() > beyond * beyond * (1.0 + 1e-9)) continue;
      const double len2 = d.squaredNorm();
      const double t = len2 > 0.0 ? std::clamp((col.position - a).dot(d) / len2, 0.0, 1.0) : 1.0;
      gap = (a + t * d - col.position).norm() - col.desc.radius;
    }
    if (gap < reach) out.push_back(Contact{static_cast<int32_t>(i), index, 0.0});
  }
}

void World::catch_late_contacts() {
  // find_contacts looked along each particle's predicted path, with its clearance as a margin; a
  // projection that carried a particle further (a chain solve pulling a whole run at once, a band
  // shrinking onto a pole) can have taken it into a collider no contact watched. Such particles are
  // looked at again along their path as it now ends, and any contact found is projected once more:
  // colliders keep the final word.
  // Only when the contacts are projected last: a host that orders a group after them (the paper's
  // evaluation order) has said that group wins.
  if (colliders_.empty() || order_.empty() || order_.back() != static_cast<int32_t>(settings_.contact_group.index))
    return;
  Group& g = groups_[settings_.contact_group.index];
  const size_t before = g.contacts.size();
  std::vector<int32_t>& moved = late_moved_;
  std::vector<uint8_t>& watched = late_watched_;
  watched.resize(x_.size());
  for (size_t c = 0; c < colliders_.size(); ++c) {
    const Collider& col = colliders_[c];
    if (!col.alive) continue;
    std::fill(watched.begin(), watched.end(), 0);
    for (size_t k = 0; k < before; ++k)
      if (g.contacts[k].collider == static_cast<int32_t>(c)) watched[g.contacts[k].particle] = 1;
    moved.clear();
    for (size_t i = 0; i < x_.size(); ++i) {
      if (w_[i] == 0.0 || watched[i]) continue;
      // (a particle that moved clearly less than its clearance is decided without the root)
      const double clearance = radius_[i] + col.desc.thickness, moved2 = (x_[i] - detected_[i]).squaredNorm();
      if (moved2 < clearance * clearance * (1.0 - 1e-9)) continue;
      if (std::sqrt(moved2) > clearance) moved.push_back(static_cast<int32_t>(i));
    }
    if (!moved.empty()) find_collider_contacts(static_cast<int32_t>(c), &moved, g.contacts);
  }
  for (size_t k = before; k < g.contacts.size(); ++k) project_contact(g.contacts[k]);
}

/// Panel faces against sphere colliders: a flat panel touching a sphere with its corners only would
/// cut into it (a 0.8 panel over a sphere of radius 1 by 0.175), so the triangles of every panel
/// mesh (both layers) take contacts of their own, at the point closest to the centre.
void World::find_face_contacts() {
  face_contacts_.clear();
  if (panel_layouts_.empty()) return;
  // A panel's faces far from a sphere stay out of its reach for some substeps: each bound set when
  // a panel is looked at (below) is kept with what it can have lost since, so a panel is looked at
  // again only once that loss could bring it within reach. Between two looks a bound loses no
  // more than three times the layout's largest particle shift (the corner it is measured from
  // moves by one, the panel's extent by two) plus how far the sphere moved. A panel skipped so
  // would have been skipped by its own look, so the contacts are the same.
  FaceReach& fr = face_reach_;
  size_t spheres = 0, panels = 0;
  for (const Collider& col : colliders_)
    if (col.alive && col.desc.shape == ColliderShape::sphere) ++spheres;
  for (const PanelLayout& l : panel_layouts_) panels += static_cast<size_t>(l.panel_count());
  if (spheres == 0) return;
  if (!fr.started || fr.bound.size() != spheres * panels || fr.sphere.size() != spheres) {
    fr.started = true;
    fr.bound.assign(spheres * panels, -std::numeric_limits<double>::infinity());
    fr.spent.assign(spheres * panel_layouts_.size(), 0.0);
    fr.sphere.clear();
    for (const Collider& col : colliders_)
      if (col.alive && col.desc.shape == ColliderShape::sphere) fr.sphere.push_back(col.position);
    fr.seen = x_;
  }
  // Per layout: the largest shift of a particle since the last look, and of its motion this substep.
  std::vector<std::pair<double, double>>& shifts = fr.shifts;
  shifts.resize(panel_layouts_.size());
  for (size_t li = 0; li < panel_layouts_.size(); ++li) {
    const PanelLayout& l = panel_layouts_[li];
    double shift2 = 0.0, motion2 = 0.0;
    for (int64_t k = 0; k < l.particle_count(); ++k) {
      const size_t i = static_cast<size_t>(l.first_particle + k);
      shift2 = std::max(shift2, (x_[i] - fr.seen[i]).squaredNorm());
      motion2 = std::max(motion2, (x_[i] - x_prev_[i]).squaredNorm());
      fr.seen[i] = x_[i];
    }
    shifts[li] = {std::sqrt(shift2), std::sqrt(motion2)};
  }
  // Each part looks at a contiguous run of a mesh's panels: the contacts stand in panel order.
  size_t sphere = 0;
  for (size_t c = 0; c < colliders_.size(); ++c) {
    const Collider& col = colliders_[c];
    if (!col.alive || col.desc.shape != ColliderShape::sphere) continue;
    const double r = col.desc.radius + col.desc.thickness;
    const double move = (col.position - col.position_prev).norm();
    const double sphere_shift = (col.position - fr.sphere[sphere]).norm();
    fr.sphere[sphere] = col.position;
    // A panel's four triangles (two a layer) that come within reach of the sphere.
    auto look_at = [&](const PanelLayout& l, int32_t p, double spent, double& bound, std::vector<FaceContact>& found) {
      // First the whole panel: its triangles are no nearer the centre than its first corner less the
      // farthest corner from that one, and move no more than its corners do. A panel out of reach by
      // that bound (and 1 um more, far beyond rounding) has no contact below; most panels are.
      const Vec3 o = x_[l.top(p, 0)];
      double extent2 = 0.0, moved2 = 0.0;
      for (int k = 0; k < 8; ++k) {
        const int32_t i = k < 4 ? l.top(p, k) : l.bottom(p, k - 4);
        extent2 = std::max(extent2, (x_[i] - o).squaredNorm());
        moved2 = std::max(moved2, (x_[i] - x_prev_[i]).squaredNorm());
      }
      const double reach = (o - col.position).norm() - std::sqrt(extent2) - r;
      bound = reach + spent;
      if (reach > std::sqrt(moved2) + move + 1e-6) return;
      for (int layer = 0; layer < 2; ++layer)
        for (int half = 0; half < 2; ++half) {
          auto corner = [&](int k, bool top) { return top ? l.top(p, k) : l.bottom(p, k); };
          const bool top = layer == 0;
          const int32_t ids[3] = {corner(0, top), corner(1 + half, top), corner(2 + half, top)};
          const int32_t partner[3] = {corner(0, !top), corner(1 + half, !top), corner(2 + half, !top)};
          if (slab_weight(ids[0], partner[0]) == 0.0 && slab_weight(ids[1], partner[1]) == 0.0 &&
              slab_weight(ids[2], partner[2]) == 0.0)
            continue;
          double moved = 0.0;
          for (int32_t i : ids) moved = std::max(moved, (x_[i] - x_prev_[i]).norm());
          const Vec3 b = closest_barycentric(col.position, x_[ids[0]], x_[ids[1]], x_[ids[2]]);
          const Vec3 q = b[0] * x_[ids[0]] + b[1] * x_[ids[1]] + b[2] * x_[ids[2]];
          if ((q - col.position).norm() - r < moved + move)
            found.push_back(FaceContact{
                {ids[0], ids[1], ids[2]}, {partner[0], partner[1], partner[2]}, static_cast<int32_t>(c), 0.0});
        }
    };
    size_t first = 0;  // the layout's first panel in the bounds of this sphere
    for (size_t li = 0; li < panel_layouts_.size(); ++li) {
      const PanelLayout& l = panel_layouts_[li];
      double& spent = fr.spent[sphere * panel_layouts_.size() + li];
      spent += 3.0 * shifts[li].first + sphere_shift;
      // Skipped when the bound, less what it can have lost, clears what the look above asks for
      // with the layout's largest motion for the panel's (and 1 nm for the sums' rounding).
      const double clear = shifts[li].second + move + 1e-6 + 1e-9;
      double* bound = fr.bound.data() + sphere * panels + first;
      pool_->collect(0, static_cast<size_t>(l.panel_count()), kFaceGrain, face_parts_, face_contacts_,
                     [&](size_t begin, size_t end, std::vector<FaceContact>& found) {
                       for (size_t p = begin; p < end; ++p)
                         if (!(bound[p] - spent > clear)) look_at(l, static_cast<int32_t>(p), spent, bound[p], found);
                     });
      first += static_cast<size_t>(l.panel_count());
    }
    ++sphere;
  }
}

double World::slab_weight(int32_t a, int32_t b) const {
  const double wa = w_[a], wb = w_[b];
  return wa > 0.0 && wb > 0.0 ? 1.0 / (1.0 / wa + 1.0 / wb) : 0.0;  // 1 / (m_a + m_b), no overflow
}

namespace {

/// One projection of a face contact (hard, unilateral: C = gap >= 0, grad_k C = b_k n, corner k and
/// its partner across the thickness moving as one particle of their joint mass, `weight`): lambda
/// accumulates the push. Returns the push added (0: none) and, in `normal_force`, the force it adds on
/// the movable corner pairs times h^2 (sum over them of b_k, times the push, along n). With
/// `push_only`, a face that is not inside is left where it is.
template <class Weight>
double project_face(FaceContact& fc, const Collider& col, std::vector<Vec3>& x, Weight weight, Vec3& normal_force,
                    bool push_only = false) {
  const Vec3& a = x[fc.ids[0]];
  const Vec3& b = x[fc.ids[1]];
  const Vec3& c = x[fc.ids[2]];
  const Vec3 bary = closest_barycentric(col.position, a, b, c);
  const Vec3 q = bary[0] * a + bary[1] * b + bary[2] * c;
  const Vec3 d = q - col.position;
  const double len = d.norm();
  if (!(len > 1e-12)) return 0.0;
  const Vec3 n = d / len;
  const double gap = len - (col.desc.radius + col.desc.thickness);
  if (push_only && !(gap < 0.0)) return 0.0;
  double ws[3], denom = 0.0, share = 0.0;
  for (int k = 0; k < 3; ++k) {
    ws[k] = weight(fc.ids[k], fc.partner[k]);
    denom += ws[k] * bary[k] * bary[k];
    if (ws[k] > 0.0) share += bary[k];
  }
  if (denom <= 0.0) return 0.0;
  const double lambda = std::max(fc.lambda - gap / denom, 0.0);
  const double dl = lambda - fc.lambda;
  fc.lambda = lambda;
  if (dl == 0.0) return 0.0;
  for (int k = 0; k < 3; ++k) {
    const Vec3 step = (ws[k] * bary[k] * dl) * n;
    x[fc.ids[k]] += step;
    x[fc.partner[k]] += step;
  }
  normal_force = (share * dl) * n;
  return dl;
}

}  // namespace

void World::project_face_contacts() {
  const auto weight = [this](int32_t a, int32_t b) { return slab_weight(a, b); };
  Vec3 unused;
  for (FaceContact& fc : face_contacts_) project_face(fc, colliders_[fc.collider], x_, weight, unused);
}

void World::find_shape_contacts(int32_t index, const std::vector<int32_t>* only, size_t begin, size_t end,
                                std::vector<Contact>& out) const {
  const Collider& col = colliders_[index];
  const ColliderGeometry& geo = *col.geometry;
  // Convex solids have a convex distance along any straight path, so a Newton step towards the
  // surface never passes it; a mesh advances by the distance alone (the distance changes at most
  // as fast as the point moves).
  const bool convex = col.desc.shape != ColliderShape::mesh;
  Vec3 lo, hi;
  shape_bounds(col.desc, geo, lo, hi);
  const Eigen::Quaterniond inv_prev = col.rotation_prev.conjugate(), inv = col.rotation.conjugate();
  for (size_t k = begin; k < end; ++k) {
    const size_t i = only ? static_cast<size_t>((*only)[k]) : k;
    if (w_[i] == 0.0) continue;
    // The particle's path in the collider's frame, from where it was against the collider's pose at
    // the start of the substep to where it is against the pose at the end: the collider's motion is
    // part of the path.
    const Vec3 a0 = inv_prev * (x_prev_[i] - col.position_prev);
    const Vec3 a1 = inv * (x_[i] - col.position);
    const double r = radius_[i] + col.desc.thickness;
    const Vec3 seg = a1 - a0;
    const double len = seg.norm();
    // As far out as a contact can be kept (the near-surface reach below: the path plus the clearance
    // twice).
    const double margin = 2.0 * r + (x_[i] - x_prev_[i]).norm();
    if ((a0.cwiseMin(a1).array() > hi.array() + margin).any() || (a0.cwiseMax(a1).array() < lo.array() - margin).any())
      continue;
    const int32_t particle = static_cast<int32_t>(i);
    Vec3 n;
    double d = shape_distance(col.desc, geo, a0, n) - r;
    if (d < 0.0) {  // inside at the start (if only by rounding): out by the way nearest to where it was
      out.push_back(Contact{particle, index, 0.0, true, n, n.dot(a0) - d});
      continue;
    }
    // Conservative advancement along the path to its first contact with the clearance surface.
    const double tol = 1e-13 * (1.0 + a0.cwiseAbs().maxCoeff() + len + r);
    double t = 0.0;
    bool hit = d <= tol;
    for (int it = 0; it < 200 && !hit && len > 0.0; ++it) {
      double rate = len;
      if (convex) {
        rate = -n.dot(seg);
        if (rate <= 0.0) break;  // moving away from a convex solid: no contact on this path
      }
      t += d / rate;
      if (t > 1.0) break;
      d = shape_distance(col.desc, geo, a0 + t * seg, n) - r;
      hit = d <= tol || it == 199;
    }
    if (hit) {
      // Held on the tangent plane where the path met the surface: it leaves the way it came.
      const Vec3 p = a0 + t * seg;
      out.push_back(Contact{particle, index, 0.0, true, n, n.dot(p) - d});
      continue;
    }
    // Near the surface at the end of the path: a contact that acts only if the particle gets within
    // its clearance. The groups projected before the contacts can move a particle further than its
    // path (cloth pulled over a box's edge by its stretch), so the reach is the path plus the
    // clearance again as a margin; an inactive contact costs one distance per projection.
    d = shape_distance(col.desc, geo, a1, n) - r;
    if (d < (x_[i] - x_prev_[i]).norm() + r) out.push_back(Contact{particle, index, 0.0, false, Vec3::Zero(), 0.0});
  }
}

void World::project_contact(Contact& ct) {
  const Collider& c = colliders_[ct.collider];
  const int32_t i = ct.particle;
  Vec3 n;
  const double gap = contact_gap(c, ct, x_[i], x_prev_[i], radius_[i] + c.desc.thickness, n);
  // Hard, unilateral: C = gap >= 0; lambda accumulates the push (a length, as w_i cancels).
  const double dl = std::max(ct.lambda - gap, 0.0) - ct.lambda;
  ct.lambda += dl;
  x_[i] += dl * n;
}

void World::project_contacts(Group& g, double /*h*/) {
  for (Contact& ct : g.contacts) project_contact(ct);
}

void World::settle_contacts_on_surface() {
  // A swept contact holds its particle on the tangent plane where the particle's path met the
  // clearance surface. A particle that slides along that plane within the substep (a chain step
  // moves a whole run at once; friction along a plane met near an edge) can end below the surface's
  // curve or edge beside it; on a convex collider it is pushed out along the closest point (a mesh
  // keeps the plane: the closest point of a thin mesh can lie on its far side). A contact at the
  // closest point is projected once more as it is at every projection: friction after the contacts
  // (between the layers of a cloth folded on a cube) can have moved its particle inside. Only when
  // the contacts are projected last, as catch_late_contacts.
  if (colliders_.empty() || order_.empty() || order_.back() != static_cast<int32_t>(settings_.contact_group.index))
    return;
  Group& g = groups_[settings_.contact_group.index];
  for (Contact& ct : g.contacts) {
    const Collider& c = colliders_[ct.collider];
    if (ct.swept && c.desc.shape == ColliderShape::mesh) continue;
    Contact closest = ct;
    closest.swept = false;
    Vec3 n;
    const int32_t i = ct.particle;
    const double gap = contact_gap(c, closest, x_[i], x_prev_[i], radius_[i] + c.desc.thickness, n);
    // A swept contact never out through the far side (a thin plate): only when the closest point's
    // normal faces the way the particle came in.
    if (gap < 0.0 && (!ct.swept || n.dot(c.rotation * ct.normal) > 0.0)) {
      x_[i] -= gap * n;
      ct.force_h2 -= (gap / w_[i]) * n;
    }
  }
  // Face contacts likewise: friction moves a face's corners by their weights in the contact point,
  // and where panels share corners that tilts their other faces; each face inside is pushed out once
  // more. Pushed only: a face outside with a multiplier left is not pulled back onto the surface
  // here, as a projection would, since that pulls the corners it shares with faces already settled
  // back into the sphere (by 1.7e-6 m on the 32 x 32 drape).
  const auto weight = [this](int32_t a, int32_t b) { return slab_weight(a, b); };
  for (FaceContact& fc : face_contacts_) {
    Vec3 push = Vec3::Zero();
    if (project_face(fc, colliders_[fc.collider], x_, weight, push, true) != 0.0) fc.force_h2 += push;
  }
}

void World::apply_collider_friction(Contact& ct, double h) {
  if (ct.lambda <= 0.0) return;
  const Collider& c = colliders_[ct.collider];
  const int32_t i = ct.particle;
  Vec3 n;
  contact_gap(c, ct, x_[i], x_prev_[i], 0.0, n);
  // The push as the solve left it, along the normal where it left the particle (the reactions).
  ct.force_h2 = (ct.lambda / w_[i]) * n;
  const Vec3 slip = (x_[i] - x_prev_[i]) - (x_[i] - collider_point_before(c, x_[i]));
  const Vec3 tangential = slip - slip.dot(n) * n;
  const double len = tangential.norm();
  const double mu_s = std::sqrt(mu_s_[i] * c.desc.friction_static);
  const double mu_k = std::sqrt(mu_k_[i] * c.desc.friction_dynamic);
  const Vec3 moved = -friction_fraction(len, ct.lambda, mu_s, mu_k, h) * tangential;
  x_[i] += moved;
  ct.force_h2 += moved / w_[i];
}

void World::apply_friction(double h) {
  // Friction (friction_fraction): the tangential slip relative to the collider is removed while it
  // is below mu times the normal push, else reduced by mu times it; mu falls from mu_s to mu_k with
  // the slip speed.
  // Different particles' contacts are independent. A particle's own (one a collider, listed
  // collider by collider, late ones after) are taken in the list's order by the one thread whose
  // range of particles holds it, so the bits do not depend on the thread count.
  Group& g = groups_[settings_.contact_group.index];
  std::vector<Contact>& contacts = g.contacts;
  if (contacts.size() < 2 * kContactGrain) {  // (too few to outweigh a hand-over)
    for (Contact& ct : contacts) apply_collider_friction(ct, h);
  } else {
    pool_->run(0, x_.size(), 1, 1, [&](size_t begin, size_t end, int) {
      for (Contact& ct : contacts)
        if (static_cast<size_t>(ct.particle) >= begin && static_cast<size_t>(ct.particle) < end)
          apply_collider_friction(ct, h);
    });
  }
  self_collision::apply_friction(self_contacts_, x_, x_prev_, w_, h);
  // Face contacts: the same rule at the contact point sum_k b_k x_k, the correction shared out as a
  // projection shares it (corner k and its partner move w_k b_k / sum_j w_j b_j^2 of it, w_k the
  // inverse of their joint mass).
  for (FaceContact& fc : face_contacts_) {
    if (fc.lambda <= 0.0) continue;
    const Collider& c = colliders_[fc.collider];
    const Vec3 bary = closest_barycentric(c.position, x_[fc.ids[0]], x_[fc.ids[1]], x_[fc.ids[2]]);
    Vec3 q = Vec3::Zero(), moved = Vec3::Zero();
    double denom = 0.0, mu_s = 0.0, mu_k = 0.0;
    for (int k = 0; k < 3; ++k) {
      const int32_t i = fc.ids[k];
      q += bary[k] * x_[i];
      moved += bary[k] * (x_[i] - x_prev_[i]);
      denom += slab_weight(i, fc.partner[k]) * bary[k] * bary[k];
      mu_s += bary[k] * mu_s_[i];
      mu_k += bary[k] * mu_k_[i];
    }
    if (denom <= 0.0) continue;
    const Vec3 n = (q - c.position).normalized();
    const Vec3 slip = moved - (q - collider_point_before(c, q));
    const Vec3 tangential = slip - slip.dot(n) * n;
    const double len = tangential.norm();
    mu_s = std::sqrt(mu_s * c.desc.friction_static);
    mu_k = std::sqrt(mu_k * c.desc.friction_dynamic);
    // lambda is the push of the contact point (in length: sum_k w_k b_k^2 lambda moves it by that).
    const double push = fc.lambda * denom;
    const Vec3 remove = friction_fraction(len, push, mu_s, mu_k, h) * tangential;
    double share = 0.0;  // of the movable corner pairs: pair k moves as a force b_k / denom remove / h^2
    for (int k = 0; k < 3; ++k) {
      const double ws = slab_weight(fc.ids[k], fc.partner[k]);
      const Vec3 step = (ws * bary[k] / denom) * remove;
      x_[fc.ids[k]] -= step;
      x_[fc.partner[k]] -= step;
      if (ws > 0.0) share += bary[k];
    }
    fc.force_h2 = share * fc.lambda * n - (share / denom) * remove;
  }
}

}  // namespace embra
