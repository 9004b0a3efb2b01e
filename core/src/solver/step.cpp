// The step: XPBD in substeps, as a recipe of named stages. step() reads:
//
//   begin_frame                hard pins' start, control.before_frame, solver arrays brought up to date
//   for each substep:
//     move_colliders           collider poses along their path over the frame
//     predict                  fields, x <- x + h v + h^2 (g + w f) (f: point, area and line loads); hard-pinned
//                              particles follow their target
//     find_contacts            particles against colliders (swept over the substep), cloth against
//     find_self_contacts       itself (self_collision.cpp), panel faces against spheres
//     find_face_contacts
//     reset_multipliers        lambda <- 0 (each substep is its own implicit solve)
//     solve                    realignment passes x iterations: pressure volumes, then the groups in
//                              their order, each `weight` times (project_group)
//     catch_late_contacts      contacts a projection carried a particle into (contacts.cpp)
//     apply_friction           collider, self and face contacts (contacts.cpp)
//     settle_contacts_on_surface  swept contacts pushed out along the closest point (contacts.cpp)
//     update_velocities        v <- (x - x_prev) / h, damped
//     check_state_in_range     a position or velocity non-finite or beyond 1e300 fails the frame
//   end_frame                  multipliers back to the constraint arrays, colliders' frame pose, clock
//   measure                    residuals per group, kinetic energy, settled flag
//
// A frame that does not complete is undone (restore) and its exception passes on.
#include "collision/collider_shapes.hpp"
#include "collision/self_collision.hpp"
#include "embra/core/limits.hpp"
#include "embra/core/world.hpp"
#include "model/kind_traits.hpp"
#include "solver/contacts.hpp"
#include "solver/kernels.hpp"
#include "solver/pin_track.hpp"
#include "solver/residuals.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <string>

namespace embra {

namespace {

/// A group's solver arrays of the islands' row kinds, in IslandPlan::kRowKind's order.
std::array<SolverArray*, IslandPlan::kRowKinds> island_rows(Group& g) {
  std::array<SolverArray*, IslandPlan::kRowKinds> rows{};
  for (int k = 0; k < IslandPlan::kRowKinds; ++k) rows[k] = &g.solve[static_cast<int>(IslandPlan::kRowKind[k])];
  return rows;
}

/// Particles per thread below which a per-particle pass is not split (a particle costs nanoseconds).
constexpr size_t kParticleGrain = 2048;

/// Calls f(begin, end) over the particles [0, n) in parts over the pool's threads: with `runs`
/// (World::particle_runs_), part p takes its runs, whatever their length; else equal ranges, none
/// under kParticleGrain. For passes where each particle reads and writes only its own state (the
/// same bits at any split).
template <class F>
void particle_ranges(ThreadPool& pool, const std::vector<std::array<int32_t, 3>>& runs, size_t n, F&& f) {
  if (runs.empty() || static_cast<size_t>(runs.back()[1]) != n)
    return pool.run(0, n, 1, kParticleGrain, [&](size_t begin, size_t end, int) { f(begin, end); });
  pool.run_parts(pool.size(), [&](int part) {
    for (const std::array<int32_t, 3>& r : runs)
      if (r[2] == part) f(static_cast<size_t>(r[0]), static_cast<size_t>(r[1]));
  });
}

/// Calls f(i) for every particle i of [0, n), over the threads as particle_ranges cuts them.
template <class F>
void each_particle(ThreadPool& pool, const std::vector<std::array<int32_t, 3>>& runs, size_t n, F&& f) {
  particle_ranges(pool, runs, n, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) f(i);
  });
}

/// passes::each_constraint over the constraints of kind K in `a`; with `pins` (the last substep of a
/// frame) the hard pins' impulses are tracked (PinTrack).
template <Kind K, class F>
void each_constraint(ThreadPool& pool, SolverArray& a, const std::vector<Vec3>& x, std::vector<Pin>* pins,
                     F&& project) {
  if (pins == nullptr || a.pinned.empty()) {
    passes::each_constraint(pool, a, project);
    return;
  }
  PinTrack<K> track(a, x, *pins);
  passes::each_colour_tracked(
      pool, a.colour_start, a.shared_tail, passes::kGrain,
      [&](size_t b, size_t e, bool, int) {
        for (size_t i = b; i < e; ++i) project(i);
      },
      track);
}

/// project_pass of a lane kernel of kind K, the hard pins' impulses tracked likewise.
template <Kind K>
void kernel_pass(ThreadPool& pool, Kernels::Pass kernel, SolverArray& a, double inv_h2, std::vector<Vec3>& x,
                 const double* w, std::vector<Pin>* pins) {
  if (pins == nullptr || a.pinned.empty()) {
    project_pass(pool, kernel, a, inv_h2, coords(x), w);
    return;
  }
  PinTrack<K> track(a, x, *pins);
  passes::each_colour_tracked(
      pool, a.colour_start, a.shared_tail, passes::kGrain,
      [&](size_t b, size_t e, bool in_lanes, int) { kernel(a, b, e, in_lanes, inv_h2, coords(x), w); }, track);
}

/// The tracked substep of islands in colours (IslandPlan: panels sharing their corners), colour by
/// colour: the islands that hold no hard-pinned particle as islands_pass projects them (split over
/// the threads), then those that do on the caller, their rows one at a time with the pass kernels
/// (which give a row the bits the island kernels give it) and the hard pins' shares tracked around
/// each row that holds a pinned particle (PinTrack). A colour's islands share no particle, so the
/// split changes no bit.
void tracked_islands(ThreadPool& pool, IslandPlan& plan, SolverArray* const* rows, double inv_h2, std::vector<Vec3>& x,
                     const double* w, std::vector<Pin>& pins, int ends) {
  const Kernels& k = kernels();
  const Kernels::Pass pass[IslandPlan::kRowKinds] = {k.distance, k.planarity, k.plane_offset};
  PinTrack<Kind::distance> distance(*rows[0], x, pins);
  PinTrack<Kind::planarity> planarity(*rows[1], x, pins);
  PinTrack<Kind::plane_offset> offset(*rows[2], x, pins);
  const auto project = [&](auto& track, int kind, size_t row) {
    const bool held = track.next(row) == row;  // the row holds a hard-pinned particle
    if (held) track.before(row, row + 1);
    pass[kind](*rows[kind], row, row + 1, false, inv_h2, coords(x), w);
    if (held) track.after(row, row + 1);
  };
  const std::vector<uint8_t>& held = plan.pinned_items;  // find_pinned_slots
  for (size_t c = 0; c + 1 < plan.colour_start.size(); ++c) {
    islands_colour(pool, plan, c, rows, inv_h2, coords(x), w, held.data(), ends);
    for (size_t i = static_cast<size_t>(plan.colour_start[c]); i < static_cast<size_t>(plan.colour_start[c + 1]); ++i)
      if (held[i] != 0)
        each_island_row(plan, i, i + 1, [&](int kind, size_t row) {
          if (kind == 0)
            project(distance, kind, row);
          else if (kind == 1)
            project(planarity, kind, row);
          else
            project(offset, kind, row);
        });
  }
}

/// Welds x0 = x1 (three multipliers each), colour by colour over the pool's threads.
void project_weld(ThreadPool& pool, SolverArray& a, double inv_h2, std::vector<Vec3>& x, const std::vector<double>& w,
                  std::vector<Pin>* pins) {
  each_constraint<Kind::weld>(pool, a, x, pins, [&](size_t i) {
    const int32_t p0 = a.ids[2 * i], p1 = a.ids[2 * i + 1];
    const double alpha = a.compliance[i] * inv_h2;
    const double denom = w[p0] + w[p1] + alpha;
    if (denom <= 0.0) return;
    const Vec3 l(a.lambda[3 * i], a.lambda[3 * i + 1], a.lambda[3 * i + 2]);
    const Vec3 dl = (-(x[p0] - x[p1]) - alpha * l) / denom;
    for (int k = 0; k < 3; ++k) a.lambda[3 * i + k] += dl[k];
    x[p0] += w[p0] * dl;
    x[p1] -= w[p1] * dl;
  });
}

/// The generic pass, through constraint_math.hpp (edge angle, tet volume, equal length, ...),
/// colour by colour over the pool's threads. A one-sided kind (KindTraits::side) that holds with no
/// multiplier left is skipped, and its accumulated multiplier is kept on its side (the tether
/// kernel's clamp, kernels.cpp).
template <Kind K>
void project_generic(ThreadPool& pool, SolverArray& a, double inv_h2, std::vector<Vec3>& x,
                     const std::vector<double>& w, std::vector<Pin>* pins) {
  constexpr int N = arity(K);
  each_constraint<K>(pool, a, x, pins, [&](size_t i) {
    const int32_t* p = &a.ids[i * N];
    auto e = KindTraits<K>::evaluate(p, x);
    if (!e.valid) return;
    if constexpr (shares_operands<K>()) {
      // A particle in two slots moves along the sum of their gradients, once: the later slot's
      // gradient joins the earlier one's and is zeroed.
      for (int k = 1; k < N; ++k)
        for (int j = 0; j < k; ++j)
          if (p[k] == p[j]) {
            e.grad[j] += e.grad[k];
            e.grad[k].setZero();
            break;
          }
    }
    const double c = KindTraits<K>::deviation(e.value, a.rest[i]);
    constexpr int side = KindTraits<K>::side;
    if constexpr (side != 0)
      if (side * c >= 0.0 && a.lambda[i] == 0.0) return;
    const double alpha = a.compliance[i] * inv_h2;
    double denom = alpha;
    for (int k = 0; k < N; ++k) denom += w[p[k]] * e.grad[k].squaredNorm();
    if (denom <= 0.0) return;
    double dl = (-c - alpha * a.lambda[i]) / denom;
    if constexpr (side > 0) dl = std::max(a.lambda[i] + dl, 0.0) - a.lambda[i];
    if constexpr (side < 0) dl = std::min(a.lambda[i] + dl, 0.0) - a.lambda[i];
    a.lambda[i] += dl;
    for (int k = 0; k < N; ++k) x[p[k]] += (w[p[k]] * dl) * e.grad[k];
  });
}

/// Adds w_k lambda grad_k C(x) of every constraint of a solver array to `out`.
template <Kind K>
void add_corrections(const SolverArray& a, const std::vector<Vec3>& x, const std::vector<double>& w,
                     std::vector<Vec3>& out) {
  constexpr int N = arity(K);
  for (size_t i = 0; i < a.size(); ++i) {
    if (a.lambda[i] == 0.0) continue;
    const int32_t* p = &a.ids[i * N];
    const auto e = KindTraits<K>::evaluate(p, x);
    if (!e.valid) continue;
    for (int k = 0; k < N; ++k) out[p[k]] += (w[p[k]] * a.lambda[i]) * e.grad[k];
  }
}

}  // namespace

void World::predict(double h, double alpha) {
  apply_fields(h, report_.time + alpha * settings_.dt - h);  // fields/fields.cpp
  const Vec3 dv = h * settings_.gravity;
  // Point loads, and the area and line loads from the positions at the substep's start (N).
  const bool distributed = !area_loads_.empty() || !line_loads_.empty();
  if (distributed) {
    load_now_ = load_;
    add_distributed_loads(x_, load_now_);
  }
  const std::vector<Vec3>& load = distributed ? load_now_ : load_;
  each_particle(*pool_, particle_runs_, x_.size(), [&](size_t i) {
    x_prev_[i] = x_[i];
    if (w_[i] == 0.0) return;
    v_[i] += dv;
    if (!load[i].isZero()) v_[i] += (h * w_[i]) * load[i];
    x_[i] += h * v_[i];
  });
  for (const Pin& p : pins_)
    if (p.alive && p.kinematic()) x_[p.particle] = (1.0 - alpha) * p.target_prev + alpha * p.target;  // exact at 1
}

void World::move_colliders(double alpha) {
  for (Collider& c : colliders_) {
    if (!c.alive) continue;
    c.position_prev = c.position;
    c.rotation_prev = c.rotation;
    // Exact at alpha = 1: the collider ends the frame precisely where the host put it.
    c.position = (1.0 - alpha) * c.frame_position + alpha * c.desc.position;
    c.rotation = alpha == 1.0 ? c.desc.rotation : c.frame_rotation.slerp(alpha, c.desc.rotation);
  }
}

void World::reset_multipliers() {
  for (int32_t slot : order_) {
    Group& g = groups_[slot];
    for (SolverArray& a : g.solve) std::fill(a.lambda.begin(), a.lambda.end(), 0.0);
    for (const IslandPlan::Shape& shape : g.islands.shapes) {
      std::fill(shape.lambda.begin(), shape.lambda.end(), 0.0);
      std::fill(shape.lambda_single.begin(), shape.lambda_single.end(), 0.0f);
    }
    std::fill(g.tethers.lambda.begin(), g.tethers.lambda.end(), 0.0);
    for (int32_t pi : g.soft_pins) pins_[pi].lambda.setZero();
    for (ShapeMatch& sm : g.shapes) std::fill(sm.lambda.begin(), sm.lambda.end(), Vec3::Zero());
  }
}

void World::find_pinned_slots() {
  pinned_any_ = false;
  const auto find = [&](SolverArray& a, int n) {
    a.pinned.clear();
    for (size_t i = 0; i < a.size(); ++i)
      for (int k = 0; k < n; ++k)
        if (const int32_t pin = hard_pin_of_[a.ids[i * n + k]]; pin >= 0)
          a.pinned.insert(a.pinned.end(), {static_cast<int32_t>(i), k, pin});
    pinned_any_ = pinned_any_ || !a.pinned.empty();
  };
  for (Group& g : groups_) {
    if (!g.alive) continue;
    for (const KindInfo& info : kKinds) find(g.solve[static_cast<int>(info.kind)], info.arity);
    find(g.tethers, arity(Kind::tether));
    IslandPlan& plan = g.islands;
    plan.pinned_items.assign(plan.items.size(), 0);
    for (size_t i = 0; i < plan.items.size(); ++i)
      each_island_row(plan, i, i + 1, [&](int kind, size_t row) {
        const std::vector<int32_t>& pinned = g.solve[static_cast<int>(IslandPlan::kRowKind[kind])].pinned;
        for (size_t j = 0; j < pinned.size(); j += 3)
          if (static_cast<size_t>(pinned[j]) == row) plan.pinned_items[i] = 1;
      });
  }
}

void World::restart_pin_impulses() {
  for (Pin& p : pins_)
    if (p.alive && p.kinematic()) p.lambda.setZero();
  for (int32_t slot : order_) {
    const Group& g = groups_[slot];
    for (const KindInfo& info : kKinds)
      visit_kind(info.kind, [&](auto k) { PinTrack<k>(g.solve[static_cast<int>(info.kind)], x_, pins_).add_all(); });
    PinTrack<Kind::tether>(g.tethers, x_, pins_).add_all();
    for (const ShapeMatch& sm : g.shapes)
      pin_shape_match(sm, std::vector<Vec3>(sm.lambda.size(), Vec3::Zero()), x_, hard_pin_of_, pins_);
  }
}

void World::realign(const std::vector<Vec3>& predicted) {
  // The hard pins take what the multipliers' pulls at x hand them, as the other particles are put
  // where those pulls take them.
  if (track_pins_) restart_pin_impulses();
  std::vector<Vec3>& corr = realign_;
  corr.assign(x_.size(), Vec3::Zero());
  // The corrections are summed in this order (floating-point sums: the order is part of the result).
  for (int32_t slot : order_) {
    const Group& g = groups_[slot];
    add_corrections<Kind::distance>(g.solve[static_cast<int>(Kind::distance)], x_, w_, corr);
    add_corrections<Kind::tether>(g.solve[static_cast<int>(Kind::tether)], x_, w_, corr);
    add_corrections<Kind::tether>(g.tethers, x_, w_, corr);
    add_corrections<Kind::edge_angle>(g.solve[static_cast<int>(Kind::edge_angle)], x_, w_, corr);
    add_corrections<Kind::dihedral>(g.solve[static_cast<int>(Kind::dihedral)], x_, w_, corr);
    add_corrections<Kind::tet_volume>(g.solve[static_cast<int>(Kind::tet_volume)], x_, w_, corr);
    add_corrections<Kind::planarity>(g.solve[static_cast<int>(Kind::planarity)], x_, w_, corr);
    add_corrections<Kind::plane_offset>(g.solve[static_cast<int>(Kind::plane_offset)], x_, w_, corr);
    add_corrections<Kind::equal_length>(g.solve[static_cast<int>(Kind::equal_length)], x_, w_, corr);
    add_corrections<Kind::conical>(g.solve[static_cast<int>(Kind::conical)], x_, w_, corr);
    add_corrections<Kind::length_min>(g.solve[static_cast<int>(Kind::length_min)], x_, w_, corr);
    add_corrections<Kind::angle_min>(g.solve[static_cast<int>(Kind::angle_min)], x_, w_, corr);
    add_corrections<Kind::angle_max>(g.solve[static_cast<int>(Kind::angle_max)], x_, w_, corr);
    add_corrections<Kind::colinear>(g.solve[static_cast<int>(Kind::colinear)], x_, w_, corr);
    add_corrections<Kind::direction>(g.solve[static_cast<int>(Kind::direction)], x_, w_, corr);
    add_corrections<Kind::cocircular>(g.solve[static_cast<int>(Kind::cocircular)], x_, w_, corr);
    add_corrections<Kind::cospherical>(g.solve[static_cast<int>(Kind::cospherical)], x_, w_, corr);
    const SolverArray& weld = g.solve[static_cast<int>(Kind::weld)];
    for (size_t i = 0; i < weld.size(); ++i) {
      const Vec3 l(weld.lambda[3 * i], weld.lambda[3 * i + 1], weld.lambda[3 * i + 2]);
      corr[weld.ids[2 * i]] += w_[weld.ids[2 * i]] * l;
      corr[weld.ids[2 * i + 1]] -= w_[weld.ids[2 * i + 1]] * l;
    }
    for (int32_t pi : g.soft_pins) corr[pins_[pi].particle] += w_[pins_[pi].particle] * pins_[pi].lambda;
    for (const ShapeMatch& sm : g.shapes)
      for (size_t i = 0; i < sm.particles.size(); ++i) corr[sm.particles[i]] += w_[sm.particles[i]] * sm.lambda[i];
    for (const Contact& ct : g.contacts) {
      if (ct.lambda == 0.0) continue;
      Vec3 n;
      contact_gap(colliders_[ct.collider], ct, x_[ct.particle], x_prev_[ct.particle], 0.0, n);
      corr[ct.particle] += ct.lambda * n;
    }
  }
  self_collision::add_corrections(self_contacts_, w_, corr);
  for (const FaceContact& fc : face_contacts_) {
    if (fc.lambda == 0.0) continue;
    const Collider& col = colliders_[fc.collider];
    const Vec3 bary = closest_barycentric(col.position, x_[fc.ids[0]], x_[fc.ids[1]], x_[fc.ids[2]]);
    const Vec3 q = bary[0] * x_[fc.ids[0]] + bary[1] * x_[fc.ids[1]] + bary[2] * x_[fc.ids[2]];
    const Vec3 n = (q - col.position).normalized();
    for (int k = 0; k < 3; ++k) {
      const Vec3 step = (slab_weight(fc.ids[k], fc.partner[k]) * bary[k] * fc.lambda) * n;
      corr[fc.ids[k]] += step;
      corr[fc.partner[k]] += step;
    }
  }
  each_particle(*pool_, particle_runs_, x_.size(), [&](size_t i) {
    if (w_[i] != 0.0) x_[i] = predicted[i] + corr[i];
  });
}

void World::project_group(Group& g, double h, bool first, int ends) {
  const double inv_h2 = 1.0 / (h * h);
  for (int32_t pi : g.soft_pins) {
    Pin& p = pins_[pi];
    const double w = w_[p.particle];
    const double alpha = p.compliance * inv_h2;
    if (w + alpha <= 0.0) continue;
    // The held part only (all of it for a point): a support's multiplier stays along its normal
    // (plane), across its line, or in its held coordinates (axes), so the particle slides freely the
    // other ways.
    if (p.support == PinSupport::polyline) {
      // Held on the closest point of the curve: inside a segment, the multiplier keeps only its part
      // across the segment (it slides along it freely); at a vertex, all of it.
      const Vec3 d = x_[p.particle] - p.target;
      const CurvePoint c = closest_point_on_polyline(p.curve, p.closed, d);
      const Vec3 lambda = c.inside_segment ? Vec3(p.lambda - c.tangent.dot(p.lambda) * c.tangent) : p.lambda;
      const Vec3 dl = (-(d - c.point) - alpha * lambda) / (w + alpha);
      p.lambda = lambda + dl;
      x_[p.particle] += w * dl;
      continue;
    }
    if (p.support == PinSupport::mesh) {
      // Held on the closest point of the mesh: inside a triangle, the multiplier keeps only its part
      // along the triangle's normal (it slides in the face freely); on an edge or at a vertex, all.
      const Vec3 d = x_[p.particle] - p.target;
      const SurfacePoint c = closest_point_on_mesh(p.curve, p.triangles, d);
      const Vec3 lambda = c.inside_face ? Vec3(c.normal.dot(p.lambda) * c.normal) : p.lambda;
      const Vec3 dl = (-(d - c.point) - alpha * lambda) / (w + alpha);
      p.lambda = lambda + dl;
      x_[p.particle] += w * dl;
      continue;
    }
    const Vec3 dl = (-p.held(x_[p.particle] - p.target) - alpha * p.lambda) / (w + alpha);
    p.lambda += dl;
    x_[p.particle] += w * dl;
  }
  double* x = coords(x_);
  const double* w = w_.data();
  std::vector<Pin>* tracked = track_pins_ ? &pins_ : nullptr;  // the last substep: find_pinned_slots
  project_weld(*pool_, g.solve[static_cast<int>(Kind::weld)], inv_h2, x_, w_, tracked);
  const Kernels& k = kernels();
  // Bending before stretching, so that stretch has the final word in a projection: a dihedral step
  // is linear in the positions and, when a fast fold turns a hinge by tenths of a radian in a substep
  // (a free hem whipping round at 7 m/s), it moves the wing and hinge particles off the lengths of
  // their edges. Projected after the stretch it left that for the next substep: edges across such
  // a fold ended 14 % long (the 128 x 128 acceptance cloth, frame 81 at 20 substeps); projected
  // before it, 2.9 %.
  project_generic<Kind::edge_angle>(*pool_, g.solve[static_cast<int>(Kind::edge_angle)], inv_h2, x_, w_, tracked);
  kernel_pass<Kind::dihedral>(*pool_, k.dihedral, g.solve[static_cast<int>(Kind::dihedral)], inv_h2, x_, w, tracked);
  // Tethers before stretching too: a tether pulls each particle on its own toward its anchor, and
  // during a whip that squeezes the edges between neighbours it pulls unequally; the stretch pass
  // after it takes that back (the 64 x 64 cloth after 200 frames: 2.05 % -> 1.16 %, 32 x 32: 2.77 %
  // -> 1.03 %).
  kernel_pass<Kind::tether>(*pool_, k.tether, g.solve[static_cast<int>(Kind::tether)], inv_h2, x_, w, tracked);
  if (settings_.realign_passes > 0)
    kernel_pass<Kind::tether>(*pool_, k.tether, g.tethers, inv_h2, x_, w, tracked);  // realignment needs multipliers
  else
    tether_runs_pass(*pool_, g.tethers, x, w);
  SolverArray& distance = g.solve[static_cast<int>(Kind::distance)];
  const auto rows = island_rows(g);
  // Islands (a panel mesh's panels, IslandPlan): the three kinds' rows island by island. Where the
  // hard pins' impulses are tracked, islands in one colour (welded panels) go in the passes, with the
  // same bits, and islands in colours one row at a time (tracked_islands). build_islands lists the
  // kinds projected above: a group with rows of any other kind keeps the passes, as those come in
  // between.
  const bool pinned_rows =
      tracked != nullptr && !(rows[0]->pinned.empty() && rows[1]->pinned.empty() && rows[2]->pinned.empty());
  const bool coloured = g.islands.colour_start.size() > 2;
  const bool islands = g.islands.active() && k.islands != nullptr && (!pinned_rows || coloured);
  // Chains in a group's first projection of a substep only (Settings::chain_solve; with realignment
  // passes, before the first of them): see chain_pass.
  if (islands && pinned_rows) {
    tracked_islands(*pool_, g.islands, rows.data(), inv_h2, x_, w, *tracked, ends);
  } else if (islands) {
    islands_pass(*pool_, g.islands, rows.data(), inv_h2, x, w, ends);
  } else if (distance.chain_start.empty() || !first) {
    kernel_pass<Kind::distance>(*pool_, k.distance, distance, inv_h2, x_, w, tracked);
  } else if (tracked == nullptr || distance.pinned.empty()) {
    chain_pass(*pool_, distance, inv_h2, x, w, chain_scratch_);
  } else {
    ChainTrack track(distance, x_, w_, hard_pin_of_, pins_);
    chain_pass(*pool_, distance, inv_h2, x, w, chain_scratch_, &track);
  }
  project_generic<Kind::tet_volume>(*pool_, g.solve[static_cast<int>(Kind::tet_volume)], inv_h2, x_, w_, tracked);
  project_generic<Kind::equal_length>(*pool_, g.solve[static_cast<int>(Kind::equal_length)], inv_h2, x_, w_, tracked);
  project_generic<Kind::conical>(*pool_, g.solve[static_cast<int>(Kind::conical)], inv_h2, x_, w_, tracked);
  // The geometry goals: length and angle ranges, co-linear, direction, co-circular, co-spherical.
  project_generic<Kind::length_min>(*pool_, g.solve[static_cast<int>(Kind::length_min)], inv_h2, x_, w_, tracked);
  project_generic<Kind::angle_min>(*pool_, g.solve[static_cast<int>(Kind::angle_min)], inv_h2, x_, w_, tracked);
  project_generic<Kind::angle_max>(*pool_, g.solve[static_cast<int>(Kind::angle_max)], inv_h2, x_, w_, tracked);
  project_generic<Kind::colinear>(*pool_, g.solve[static_cast<int>(Kind::colinear)], inv_h2, x_, w_, tracked);
  project_generic<Kind::direction>(*pool_, g.solve[static_cast<int>(Kind::direction)], inv_h2, x_, w_, tracked);
  project_generic<Kind::cocircular>(*pool_, g.solve[static_cast<int>(Kind::cocircular)], inv_h2, x_, w_, tracked);
  project_generic<Kind::cospherical>(*pool_, g.solve[static_cast<int>(Kind::cospherical)], inv_h2, x_, w_, tracked);
  if (!islands) {
    kernel_pass<Kind::planarity>(*pool_, k.planarity, *rows[1], inv_h2, x_, w, tracked);
    kernel_pass<Kind::plane_offset>(*pool_, k.plane_offset, *rows[2], inv_h2, x_, w, tracked);
  }
  // Shape matches, one set at a time in the order added (serial: the same bits at any thread count).
  for (ShapeMatch& sm : g.shapes) {
    if (tracked == nullptr) {
      project_shape_match(sm, inv_h2, inv_mass_, w_, x_, shape_weights_);
      continue;
    }
    const std::vector<Vec3> before = sm.lambda;
    project_shape_match(sm, inv_h2, inv_mass_, w_, x_, shape_weights_);
    pin_shape_match(sm, before, x_, hard_pin_of_, pins_);
  }
  // Self contacts first, collider contacts last: a collider (kinematic) has the final word.
  if (!self_contacts_.empty() && &g == &groups_[settings_.contact_group.index])
    self_collision::project(self_contacts_, x_, w_);
  if (!g.contacts.empty()) project_contacts(g, h);
  if (!face_contacts_.empty() && &g == &groups_[settings_.contact_group.index]) project_face_contacts();
}

void World::chebyshev_step(int iteration, double rho, double& omega) {
  // Wang (2015), "A Chebyshev semi-iterative approach for accelerating projective and position-based
  // dynamics": x^(k+1) <- omega_(k+1) (x^(k+1) - x^(k-1)) + x^(k-1) with omega_2 = 2 / (2 - rho^2),
  // omega_(k+1) = 4 / (4 - rho^2 omega_k), the first two iterations left as they are, and the last
  // one too, so that a plain pass (contacts last) has the final word. Positions of movable particles
  // only; the multipliers keep what the projections accumulated. chebyshev_now_ holds the positions
  // this iteration started from (solve set it before the first) and chebyshev_prev_ those the one
  // before started from: the two swap, and the pass over the particles that takes the step keeps its
  // result as the positions the next iteration starts from.
  constexpr int kStart = 2;
  if (iteration + 1 >= settings_.iterations) return;  // the last iteration: nothing after it reads them
  const bool extrapolate = iteration >= kStart;
  if (extrapolate) omega = iteration == kStart ? 2.0 / (2.0 - rho * rho) : 4.0 / (4.0 - rho * rho * omega);
  chebyshev_prev_.swap(chebyshev_now_);
  chebyshev_now_.resize(x_.size());
  // Over the raw coordinates, the step written out per coordinate as Vec3's would compute it (the
  // same bits), then the range copied whole: the Vec3 form spilled each point through the stack.
  double* x = coords(x_);
  double* start = coords(chebyshev_now_);  // where the iteration before this one started
  const double* w = w_.data();
  particle_ranges(*pool_, particle_runs_, x_.size(), [&](size_t begin, size_t end) {
    if (extrapolate)
      for (size_t i = begin; i < end; ++i) {
        if (w[i] == 0.0) continue;
        for (size_t k = 3 * i; k < 3 * i + 3; ++k) x[k] = omega * (x[k] - start[k]) + start[k];
      }
    std::memcpy(start + 3 * begin, x + 3 * begin, 3 * (end - begin) * sizeof(double));
  });
  // The hard pins' impulses likewise: the step is a weighted sum of two iterates (weights adding to
  // 1), and what the pins took balances the other particles' motion in each.
  if (track_pins_) {
    pin_chebyshev_prev_.swap(pin_chebyshev_now_);
    pin_chebyshev_now_.resize(pins_.size());
    for (size_t i = 0; i < pins_.size(); ++i) {
      const Vec3 before = pin_chebyshev_now_[i];
      if (extrapolate && pins_[i].alive && pins_[i].kinematic())
        pins_[i].lambda = omega * (pins_[i].lambda - before) + before;
      pin_chebyshev_now_[i] = pins_[i].lambda;
    }
  }
}

void World::update_velocities(double h) {
  const double inv_h = 1.0 / h;
  particle_ranges(*pool_, particle_runs_, x_.size(), [&](size_t begin, size_t end) {
    double rate_before = 0.0, decay = 1.0;  // exp(-rate h), computed again only when the rate changes
    for (size_t i = begin; i < end; ++i) {
      v_[i] = (x_[i] - x_prev_[i]) * inv_h;
      const double rate = settings_.damping + damping_[i];
      if (rate > 0.0) {
        if (rate != rate_before) rate_before = rate, decay = std::exp(-rate * h);
        v_[i] *= decay;
      }
    }
  });
}

void World::check_state_in_range() {
  // A position or velocity non-finite or beyond limits::kMaxAbsValue (a state no scene could hold:
  // it would not load back) fails the frame. NaN fails every comparison, so it is never in range.
  const auto in_range = [&](size_t i) {
    return (x_[i].array().abs() <= limits::kMaxAbsValue).all() && (v_[i].array().abs() <= limits::kMaxAbsValue).all();
  };
  std::atomic<bool> bad_found{false};
  each_particle(*pool_, particle_runs_, x_.size(), [&](size_t i) {
    if (!in_range(i)) bad_found.store(true, std::memory_order_relaxed);
  });
  if (!bad_found.load(std::memory_order_relaxed)) return;
  // The frame fails: name the first such particle (lowest index), found on this thread.
  size_t i = 0;
  while (in_range(i)) ++i;
  const int32_t bad = static_cast<int32_t>(i);
  warning_.frame = report_.frame;
  warning_.particle = bad;
  warning_.message = "non-finite position or velocity (or beyond 1e300) at particle " + std::to_string(bad) +
                     " in frame " + std::to_string(report_.frame) +
                     "; the world was restored to the start of the frame";
  throw Error(ErrorCode::numerical, warning_.message);
}

void World::measure() {
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  double all_max = 0.0, all_sq = 0.0;
  int64_t all_n = 0;
  // Per kind: max, sum of squares, count (StepReport::by_kind).
  std::array<double, kResidualKinds> kind_max{}, kind_sq{};
  std::array<int64_t, kResidualKinds> kind_n{};
  const auto add = [&](int kind, double r, double& max, double& sq) {
    max = std::max(max, r);
    sq += r * r;
    kind_max[kind] = std::max(kind_max[kind], r);
    kind_sq[kind] += r * r;
    ++kind_n[kind];
  };
  for (int32_t slot : order_) {
    Group& g = groups_[slot];
    double max = 0.0, sq = 0.0;
    int64_t n = 0;
    // Every kind with a function, in table order, then the welds (three multipliers each).
    for (const KindInfo& info : kKinds)
      visit_kind(info.kind, [&](auto k) {
        if constexpr (k != Kind::weld) {
          const SolverArray& a = g.solve[static_cast<int>(info.kind)];
          double kmax = 0.0, ksq = 0.0;
          residuals<k>(*pool_, a, inv_h2, x_, kmax, ksq, measure_values_);
          const int kind = static_cast<int>(info.kind);
          max = std::max(max, kmax);
          sq += ksq;
          kind_max[kind] = std::max(kind_max[kind], kmax);
          kind_sq[kind] += ksq;
          kind_n[kind] += static_cast<int64_t>(a.size());
        }
      });
    for (const SolverArray& a : g.solve) n += static_cast<int64_t>(a.size());
    const SolverArray& weld = g.solve[static_cast<int>(Kind::weld)];
    for (size_t i = 0; i < weld.size(); ++i) {
      const Vec3 l(weld.lambda[3 * i], weld.lambda[3 * i + 1], weld.lambda[3 * i + 2]);
      add(static_cast<int>(Kind::weld),
          (x_[weld.ids[2 * i]] - x_[weld.ids[2 * i + 1]] + weld.compliance[i] * inv_h2 * l).norm(), max, sq);
    }
    for (int32_t pi : g.soft_pins) {
      const Pin& p = pins_[pi];
      add(kResidualPins, (p.held(x_[p.particle] - p.target) + p.compliance * inv_h2 * p.lambda).norm(), max, sq);
      ++n;
    }
    for (const Contact& ct : g.contacts) {
      Vec3 normal;
      const Collider& c = colliders_[ct.collider];
      const double gap =
          contact_gap(c, ct, x_[ct.particle], x_prev_[ct.particle], radius_[ct.particle] + c.desc.thickness, normal);
      add(kResidualContacts, std::max(-gap, 0.0), max, sq);
      ++n;
    }
    if (&g == &groups_[settings_.contact_group.index])
      for (const FaceContact& fc : face_contacts_) {
        const Collider& col = colliders_[fc.collider];
        const Vec3 bary = closest_barycentric(col.position, x_[fc.ids[0]], x_[fc.ids[1]], x_[fc.ids[2]]);
        const Vec3 q = bary[0] * x_[fc.ids[0]] + bary[1] * x_[fc.ids[1]] + bary[2] * x_[fc.ids[2]];
        add(kResidualContacts, std::max(col.desc.radius + col.desc.thickness - (q - col.position).norm(), 0.0), max,
            sq);
        ++n;
      }
    g.report.count = n;
    g.report.residual_max = max;
    g.report.residual_rms = n > 0 ? std::sqrt(sq / static_cast<double>(n)) : 0.0;
    all_max = std::max(all_max, max);
    all_sq += sq;
    all_n += n;
  }
  // Hard pins hold exactly; their residual is the distance left to the target.
  for (const Pin& p : pins_)
    if (p.alive && p.kinematic()) {
      const double r = (x_[p.particle] - p.target).norm();
      all_max = std::max(all_max, r);
      kind_max[kResidualPins] = std::max(kind_max[kResidualPins], r);
      kind_sq[kResidualPins] += r * r;
      ++kind_n[kResidualPins];
    }
  for (int k = 0; k < kResidualKinds; ++k)
    report_.by_kind[k] = KindResidual{kind_n[k], kind_max[k],
                                      kind_n[k] > 0 ? std::sqrt(kind_sq[k] / static_cast<double>(kind_n[k])) : 0.0};
  double ke = 0.0, vmax = 0.0;
  for (size_t i = 0; i < x_.size(); ++i) {
    const double v2 = v_[i].squaredNorm();
    if (inv_mass_[i] > 0.0) ke += 0.5 * v2 / inv_mass_[i];
    vmax = std::max(vmax, v2);
  }
  report_.kinetic_energy = ke;
  report_.max_speed = std::sqrt(vmax);
  report_.residual_max = all_max;
  report_.residual_rms = all_n > 0 ? std::sqrt(all_sq / static_cast<double>(all_n)) : 0.0;
  report_.constraint_count = all_n;
  report_.contact_count = static_cast<int64_t>(groups_[settings_.contact_group.index].contacts.size() +
                                               self_contacts_.size() + face_contacts_.size());
  report_.settled = report_.max_speed <= settings_.settle_speed;
}

World::FrameStart World::frame_start() const {
  FrameStart f;
  f.x = x_;
  f.v = v_;
  if (settings_.contact_group.index < groups_.size()) f.contacts = groups_[settings_.contact_group.index].contacts;
  f.self_contacts = self_contacts_;
  f.face_contacts = face_contacts_;
  for (const Pin& p : pins_) {
    f.pin_lambda.push_back(p.lambda);
    f.pin_target.push_back(p.target);
  }
  for (const Collider& c : colliders_) {
    f.collider_position.push_back(c.desc.position);
    f.collider_rotation.push_back(c.desc.rotation);
  }
  for (const BodyInfo& b : bodies_) f.rest_scale.push_back({b.rest_scale, b.rest_scale_u, b.rest_scale_v});
  for (const Group& g : groups_) f.tether_lambda.push_back(g.tethers.lambda);
  f.gravity = settings_.gravity;
  return f;
}

void World::restore(const FrameStart& f) {
  x_ = f.x;
  v_ = f.v;
  x_prev_ = f.x;
  for (size_t i = 0; i < pins_.size(); ++i) {
    pins_[i].lambda = f.pin_lambda[i];
    pins_[i].target = f.pin_target[i];
  }
  for (size_t i = 0; i < colliders_.size(); ++i) {
    Collider& c = colliders_[i];
    c.desc.position = f.collider_position[i];
    c.desc.rotation = f.collider_rotation[i];
    c.position = c.position_prev = c.frame_position;
    c.rotation = c.rotation_prev = c.frame_rotation;
  }
  for (size_t i = 0; i < bodies_.size(); ++i) {
    BodyInfo& b = bodies_[i];
    if (b.rest_scale != f.rest_scale[i][0] || b.rest_scale_u != f.rest_scale[i][1] ||
        b.rest_scale_v != f.rest_scale[i][2]) {
      b.rest_scale = f.rest_scale[i][0];
      b.rest_scale_u = f.rest_scale[i][1];
      b.rest_scale_v = f.rest_scale[i][2];
      rest_dirty_ = true;
    }
  }
  settings_.gravity = f.gravity;
  // The multipliers the reports read (forces, the worst constraints, reactions) go back to the last
  // completed frame's (end_frame's copy, reversed), and so do the contacts (each substep finds its
  // own afresh; the last completed frame's carry the forces that are saved and reported).
  for (Group& g : groups_) {
    for (int k = 0; k < kKindCount && !solver_dirty_; ++k) {
      SolverArray& a = g.solve[k];
      const std::vector<double>& kept = g.arrays[k].lambda;
      const size_t per = static_cast<size_t>(multipliers(static_cast<Kind>(k)));
      for (size_t i = 0; i < a.size(); ++i)
        for (size_t c = 0; c < per; ++c) {
          const size_t from = per * static_cast<size_t>(a.source[i]) + c;
          a.lambda[per * i + c] = from < kept.size() ? kept[from] : 0.0;
        }
    }
    g.contacts.clear();
  }
  // The tethers' multipliers are read where the solve left them (saved and reported): back to the
  // frame's start, or to zero where the frame rebuilt the solver with other tethers.
  for (size_t slot = 0; slot < groups_.size(); ++slot) {
    std::vector<double>& lambda = groups_[slot].tethers.lambda;
    if (slot < f.tether_lambda.size() && f.tether_lambda[slot].size() == lambda.size())
      lambda = f.tether_lambda[slot];
    else
      std::fill(lambda.begin(), lambda.end(), 0.0);
  }
  if (settings_.contact_group.index < groups_.size()) groups_[settings_.contact_group.index].contacts = f.contacts;
  face_contacts_ = f.face_contacts;
  self_contacts_ = f.self_contacts;
}

void World::step(const StepControl& control) {
  // Kept to restore a frame that does not complete: the call must leave the world as it found it.
  // (The constraints' multipliers live in the solver arrays during the step and are only copied
  // back to the constraint arrays once the frame has succeeded.)
  const FrameStart start = frame_start();
  try {
    begin_frame(control);
    const int substeps = settings_.substeps;
    const double h = settings_.dt / substeps;
    for (int32_t slot : order_)  // the rows' operands of islands in single precision, for the frame
      if (Group& g = groups_[slot]; g.islands.active())
        island_operands(g.islands, island_rows(g).data(), 1.0 / (h * h));
    face_reach_.started = false;  // the faces' bounds hold over this frame's substeps
    for (int s = 0; s < substeps; ++s) {
      const double alpha = static_cast<double>(s + 1) / substeps;
      move_colliders(alpha);
      predict(h, alpha);
      find_contacts();
      find_self_contacts();
      find_face_contacts();
      // The reactions read the last substep: there the hard pins' impulses are tracked.
      if (s + 1 == substeps) {
        for (Pin& p : pins_)
          if (p.alive && p.kinematic()) p.lambda.setZero();
        track_pins_ = pinned_any_;
        for (int32_t slot : order_)  // shape matches are added without rebuilding the solver arrays
          for (const ShapeMatch& sm : groups_[slot].shapes)
            for (int32_t p : sm.particles) track_pins_ = track_pins_ || hard_pin_of_[p] >= 0;
      }
      reset_multipliers();
      solve(h, control, s + 1 == substeps);
      // The global solve's Newton steps are not tracked: without a realignment after them, the
      // impulses are read from the multipliers where the substep ends.
      if (track_pins_ && settings_.global_solve && settings_.realign_passes == 0) restart_pin_impulses();
      track_pins_ = false;
      catch_late_contacts();
      apply_friction(h);
      settle_contacts_on_surface();
      update_velocities(h);
      check_state_in_range();
    }
  } catch (...) {
    track_pins_ = false;
    restore(start);
    throw;
  }
  end_frame();
  measure();
  apply_plasticity();
}

void World::begin_frame(const StepControl& control) {
  // A hard pin's particle glides from where it starts the frame (where the host's
  // set_positions put it, or the pin's last target) to the target: derived from the state, so a
  // saved and reloaded world steps the same.
  for (Pin& p : pins_)
    if (p.alive && p.kinematic()) p.target_prev = x_[p.particle];
  if (control.before_frame) control.before_frame(*this);
  if (solver_dirty_)
    rebuild_solver();
  else if (rest_dirty_)
    refresh_rest();
}

void World::solve(double h, const StepControl& control, bool last) {
  if (settings_.realign_passes > 0) predicted_ = x_;
  if (settings_.global_solve) global_step(h);
  for (int pass = 0; pass <= settings_.realign_passes; ++pass) {
    if (pass > 0) realign(predicted_);
    // Chebyshev acceleration acts on iterations 2 .. iterations - 2 (chebyshev_step): none below 4.
    const double rho = settings_.iterations > 3 ? settings_.chebyshev_rho_milli / 1000.0 : 0.0;
    double omega = 1.0;
    if (rho > 0.0) {  // the positions the first iteration starts from (chebyshev_step moves them on)
      chebyshev_now_ = x_;
      if (track_pins_) {
        pin_chebyshev_now_.resize(pins_.size());
        for (size_t i = 0; i < pins_.size(); ++i) pin_chebyshev_now_[i] = pins_[i].lambda;
      }
    }
    for (int it = 0; it < settings_.iterations; ++it) {
      if (control.cancel != nullptr && control.cancel->load(std::memory_order_relaxed))
        throw Error(ErrorCode::cancelled, "the step was cancelled in frame " + std::to_string(report_.frame) +
                                              "; the world was restored to the start of the frame");
      project_volumes(h);  // fields/fields.cpp
      for (int32_t slot : order_) {
        Group& g = groups_[slot];
        // The group's first projection in the substep takes the chain solve's turn (chain_pass).
        for (int k = 0; k < g.desc.weight; ++k) {
          // The islands take the arrays' multipliers only where a global solve or a pass before set
          // them: after reset_multipliers both are zero.
          const bool set = settings_.global_solve != 0 || pass > 0;
          const bool give = last || settings_.realign_passes > 0;
          const int ends = (set && it == 0 && k == 0 ? kIslandsTake : 0) |
                           (give && it + 1 == settings_.iterations && k + 1 == g.desc.weight ? kIslandsGive : 0);
          project_group(g, h, pass == 0 && it == 0 && k == 0, ends);
        }
      }
      if (rho > 0.0) chebyshev_step(it, rho, omega);
    }
  }
}

void World::end_frame() {
  for (Group& g : groups_)
    for (int k = 0; k < kKindCount; ++k) {
      const SolverArray& a = g.solve[k];
      const int per = multipliers(static_cast<Kind>(k));
      for (size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < per; ++c) g.arrays[k].lambda[per * a.source[i] + c] = a.lambda[per * i + c];
    }
  for (Collider& c : colliders_)
    if (c.alive) {
      c.frame_position = c.desc.position;
      c.frame_rotation = c.desc.rotation;
    }
  report_.frame += 1;
  report_.time += settings_.dt;
}

}  // namespace embra
