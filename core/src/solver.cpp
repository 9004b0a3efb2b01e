// The step: XPBD in substeps, as a recipe of named stages.
//
//   for each substep:
//     predict          x <- x + h v + h^2 g; hard-pinned particles follow their target
//     find_contacts    particle against colliders, swept from the start to the end of the substep
//     reset multipliers lambda <- 0 (each substep is its own implicit solve)
//     project groups   in the user's order, each `weight` times, `iterations` times over
//     update_velocities v <- (x - x_prev) / h, friction, damping
//   measure            residuals per group, kinetic energy, settled flag
#include "embra/core/world.hpp"

#include <algorithm>
#include <cmath>

namespace embra {

namespace {

template <int N>
void apply(const int32_t* ids, const ConstraintEval<N>& e, double dl, std::vector<Vec3>& x,
           const std::vector<double>& w) {
  for (int k = 0; k < N; ++k) x[ids[k]] += (w[ids[k]] * dl) * e.grad[k];
}

template <int N>
double weighted_norm(const int32_t* ids, const ConstraintEval<N>& e, const std::vector<double>& w) {
  double s = 0.0;
  for (int k = 0; k < N; ++k) s += w[ids[k]] * e.grad[k].squaredNorm();
  return s;
}

template <Kind K>
auto evaluate(const int32_t* p, const std::vector<Vec3>& x) {
  if constexpr (K == Kind::distance || K == Kind::tether)
    return eval_distance(x[p[0]], x[p[1]]);
  else if constexpr (K == Kind::edge_angle)
    return eval_edge_angle(x[p[0]], x[p[1]], x[p[2]]);
  else if constexpr (K == Kind::dihedral)
    return eval_dihedral(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
  else
    return eval_tet_volume(x[p[0]], x[p[1]], x[p[2]], x[p[3]]);
}

/// C(x) - rest, with angles wrapped so a hinge never takes the long way round.
template <Kind K>
double deviation(double value, double rest) {
  if constexpr (K == Kind::dihedral)
    return wrap_angle(value - rest);
  else
    return value - rest;
}

/// One Gauss-Seidel pass of XPBD over a plain constraint array of kind K.
template <Kind K>
void project_array(ConstraintArray& a, double inv_h2, std::vector<Vec3>& x, const std::vector<double>& w) {
  constexpr int N = K == Kind::distance || K == Kind::tether ? 2 : K == Kind::edge_angle ? 3 : 4;
  const size_t n = a.size();
  for (size_t i = 0; i < n; ++i) {
    const int32_t* p = &a.ids[i * N];
    const auto e = evaluate<K>(p, x);
    if (!e.valid) continue;
    const double c = deviation<K>(e.value, a.rest_now[i]);
    double& lambda = a.lambda[i];
    if constexpr (K == Kind::tether)
      if (c <= 0.0 && lambda == 0.0) continue;
    const double alpha = a.compliance[i] * inv_h2;
    const double denom = weighted_norm<N>(p, e, w) + alpha;
    if (denom <= 0.0) continue;
    double dl = (-c - alpha * lambda) / denom;
    if constexpr (K == Kind::tether) dl = std::min(lambda + dl, 0.0) - lambda;  // pull only
    lambda += dl;
    apply<N>(p, e, dl, x, w);
  }
}

/// XPBD residual |C + alpha~ lambda| (for a tether only while it pulls or is overstretched).
template <Kind K>
void residuals(const ConstraintArray& a, double inv_h2, const std::vector<Vec3>& x, double& max, double& sum_sq) {
  constexpr int N = K == Kind::distance || K == Kind::tether ? 2 : K == Kind::edge_angle ? 3 : 4;
  for (size_t i = 0; i < a.size(); ++i) {
    const auto e = evaluate<K>(&a.ids[i * N], x);
    const double c = deviation<K>(e.value, a.rest_now[i]);
    double r = c + a.compliance[i] * inv_h2 * a.lambda[i];
    if constexpr (K == Kind::tether)
      if (a.lambda[i] == 0.0) r = std::max(c, 0.0);
    r = std::abs(r);
    max = std::max(max, r);
    sum_sq += r * r;
  }
}

/// Position of the collider's material point now at `x`, as it was at the start of the substep.
Vec3 collider_point_before(const Collider& c, const Vec3& x) {
  const Vec3 local = c.rotation.conjugate() * (x - c.position);
  return c.position_prev + c.rotation_prev * local;
}

}  // namespace

void World::predict(double h, double alpha) {
  const Vec3 dv = h * settings_.gravity;
  const size_t n = x_.size();
  for (size_t i = 0; i < n; ++i) {
    x_prev_[i] = x_[i];
    if (w_[i] == 0.0) continue;
    v_[i] += dv;
    x_[i] += h * v_[i];
  }
  for (const Pin& p : pins_)
    if (p.alive && p.compliance == 0.0)
      x_[p.particle] = (1.0 - alpha) * p.target_prev + alpha * p.target;  // exact at 1
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

void World::find_contacts() {
  Group& g = groups_[settings_.contact_group.index];
  g.contacts.clear();
  for (size_t c = 0; c < colliders_.size(); ++c) {
    const Collider& col = colliders_[c];
    if (!col.alive) continue;
    const Vec3 normal = col.rotation * Vec3::UnitZ();
    for (size_t i = 0; i < x_.size(); ++i) {
      if (w_[i] == 0.0) continue;
      const double reach = radius_[i] + col.desc.thickness + (x_[i] - x_prev_[i]).norm();
      double gap;
      if (col.desc.shape == ColliderShape::plane) {
        gap = normal.dot(x_[i] - col.position);
      } else {
        // The closest point of the swept segment to the sphere's centre catches a particle that
        // crosses the whole sphere within one substep.
        const Vec3 a = x_prev_[i], d = x_[i] - x_prev_[i];
        const double len2 = d.squaredNorm();
        const double t = len2 > 0.0 ? std::clamp((col.position - a).dot(d) / len2, 0.0, 1.0) : 1.0;
        gap = (a + t * d - col.position).norm() - col.desc.radius;
      }
      if (gap < reach) g.contacts.push_back(Contact{static_cast<int32_t>(i), static_cast<int32_t>(c), 0.0});
    }
  }
}

void World::reset_multipliers() {
  for (int32_t slot : order_) {
    Group& g = groups_[slot];
    for (ConstraintArray& a : g.arrays) std::fill(a.lambda.begin(), a.lambda.end(), 0.0);
    for (int32_t pi : g.soft_pins) pins_[pi].lambda.setZero();
  }
}

void World::project_group(Group& g, double h) {
  const double inv_h2 = 1.0 / (h * h);
  for (int32_t pi : g.soft_pins) {
    Pin& p = pins_[pi];
    const double w = w_[p.particle];
    const double alpha = p.compliance * inv_h2;
    if (w + alpha <= 0.0) continue;
    const Vec3 dl = (-(x_[p.particle] - p.target) - alpha * p.lambda) / (w + alpha);
    p.lambda += dl;
    x_[p.particle] += w * dl;
  }
  ConstraintArray& weld = g.arrays[static_cast<int>(Kind::weld)];
  for (size_t i = 0; i < weld.size(); ++i) {
    const int32_t a = weld.ids[2 * i], b = weld.ids[2 * i + 1];
    const double alpha = weld.compliance[i] * inv_h2;
    const double denom = w_[a] + w_[b] + alpha;
    if (denom <= 0.0) continue;
    const Vec3 l(weld.lambda[3 * i], weld.lambda[3 * i + 1], weld.lambda[3 * i + 2]);
    const Vec3 dl = (-(x_[a] - x_[b]) - alpha * l) / denom;
    for (int k = 0; k < 3; ++k) weld.lambda[3 * i + k] += dl[k];
    x_[a] += w_[a] * dl;
    x_[b] -= w_[b] * dl;
  }
  project_array<Kind::distance>(g.arrays[0], inv_h2, x_, w_);
  project_array<Kind::tether>(g.arrays[5], inv_h2, x_, w_);
  project_array<Kind::edge_angle>(g.arrays[1], inv_h2, x_, w_);
  project_array<Kind::dihedral>(g.arrays[2], inv_h2, x_, w_);
  project_array<Kind::tet_volume>(g.arrays[3], inv_h2, x_, w_);
  if (!g.contacts.empty()) project_contacts(g, h);
}

namespace {
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

void World::project_contacts(Group& g, double /*h*/) {
  for (Contact& ct : g.contacts) {
    const Collider& c = colliders_[ct.collider];
    const int32_t i = ct.particle;
    Vec3 n;
    const double gap = collider_gap(c, x_[i], x_prev_[i], n) - radius_[i] - c.desc.thickness;
    // Hard, unilateral: C = gap >= 0; lambda accumulates the push (a length, as w_i cancels).
    const double dl = std::max(ct.lambda - gap, 0.0) - ct.lambda;
    ct.lambda += dl;
    x_[i] += dl * n;
  }
}

void World::update_velocities(double h) {
  // Friction (Macklin et al. 2014): the tangential slip relative to the collider is removed while
  // it is below mu_s times the normal push, else reduced by mu_k times it.
  Group& g = groups_[settings_.contact_group.index];
  for (const Contact& ct : g.contacts) {
    if (ct.lambda <= 0.0) continue;
    const Collider& c = colliders_[ct.collider];
    const int32_t i = ct.particle;
    Vec3 n;
    collider_gap(c, x_[i], x_prev_[i], n);
    const Vec3 slip = (x_[i] - x_prev_[i]) - (x_[i] - collider_point_before(c, x_[i]));
    const Vec3 tangential = slip - slip.dot(n) * n;
    const double len = tangential.norm();
    const double mu_s = std::sqrt(mu_s_[i] * c.desc.friction_static);
    const double mu_k = std::sqrt(mu_k_[i] * c.desc.friction_dynamic);
    if (len < mu_s * ct.lambda)
      x_[i] -= tangential;
    else if (len > 0.0)
      x_[i] -= tangential * std::min(mu_k * ct.lambda / len, 1.0);
  }
  const double inv_h = 1.0 / h;
  for (size_t i = 0; i < x_.size(); ++i) {
    v_[i] = (x_[i] - x_prev_[i]) * inv_h;
    const double rate = settings_.damping + damping_[i];
    if (rate > 0.0) v_[i] *= std::exp(-rate * h);
  }
}

int32_t World::first_non_finite() const {
  for (size_t i = 0; i < x_.size(); ++i)
    if (!x_[i].allFinite() || !v_[i].allFinite()) return static_cast<int32_t>(i);
  return -1;
}

void World::measure() {
  const double h = settings_.dt / settings_.substeps;
  const double inv_h2 = 1.0 / (h * h);
  double all_max = 0.0, all_sq = 0.0;
  int64_t all_n = 0;
  for (int32_t slot : order_) {
    Group& g = groups_[slot];
    double max = 0.0, sq = 0.0;
    int64_t n = 0;
    residuals<Kind::distance>(g.arrays[0], inv_h2, x_, max, sq);
    residuals<Kind::edge_angle>(g.arrays[1], inv_h2, x_, max, sq);
    residuals<Kind::dihedral>(g.arrays[2], inv_h2, x_, max, sq);
    residuals<Kind::tet_volume>(g.arrays[3], inv_h2, x_, max, sq);
    residuals<Kind::tether>(g.arrays[5], inv_h2, x_, max, sq);
    for (const ConstraintArray& a : g.arrays) n += static_cast<int64_t>(a.size());
    const ConstraintArray& weld = g.arrays[static_cast<int>(Kind::weld)];
    for (size_t i = 0; i < weld.size(); ++i) {
      const Vec3 l(weld.lambda[3 * i], weld.lambda[3 * i + 1], weld.lambda[3 * i + 2]);
      const double r = (x_[weld.ids[2 * i]] - x_[weld.ids[2 * i + 1]] + weld.compliance[i] * inv_h2 * l).norm();
      max = std::max(max, r);
      sq += r * r;
    }
    for (int32_t pi : g.soft_pins) {
      const Pin& p = pins_[pi];
      const double r = (x_[p.particle] - p.target + p.compliance * inv_h2 * p.lambda).norm();
      max = std::max(max, r);
      sq += r * r;
      ++n;
    }
    for (const Contact& ct : g.contacts) {
      Vec3 normal;
      const Collider& c = colliders_[ct.collider];
      const double gap =
          collider_gap(c, x_[ct.particle], x_prev_[ct.particle], normal) - radius_[ct.particle] - c.desc.thickness;
      const double r = std::max(-gap, 0.0);
      max = std::max(max, r);
      sq += r * r;
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
    if (p.alive && p.compliance == 0.0) all_max = std::max(all_max, (x_[p.particle] - p.target).norm());
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
  report_.contact_count = static_cast<int64_t>(groups_[settings_.contact_group.index].contacts.size());
  report_.settled = report_.max_speed <= settings_.settle_speed;
}

void World::step() {
  if (rest_dirty_) refresh_rest();
  // Kept to restore on a numerical failure: the call must leave the world as it found it.
  const std::vector<Vec3> x0 = x_, v0 = v_;
  std::vector<std::vector<double>> lambdas0;
  for (const Group& g : groups_)
    for (const ConstraintArray& a : g.arrays) lambdas0.push_back(a.lambda);
  std::vector<Vec3> pin_lambda0;
  for (const Pin& p : pins_) pin_lambda0.push_back(p.lambda);

  const int substeps = settings_.substeps;
  const double h = settings_.dt / substeps;
  for (int s = 0; s < substeps; ++s) {
    const double alpha = static_cast<double>(s + 1) / substeps;
    move_colliders(alpha);
    predict(h, alpha);
    find_contacts();
    reset_multipliers();
    for (int it = 0; it < settings_.iterations; ++it)
      for (int32_t slot : order_) {
        Group& g = groups_[slot];
        for (int k = 0; k < g.desc.weight; ++k) project_group(g, h);
      }
    update_velocities(h);
    const int32_t bad = first_non_finite();
    if (bad >= 0) {
      x_ = x0;
      v_ = v0;
      x_prev_ = x0;
      size_t k = 0;
      for (Group& g : groups_)
        for (ConstraintArray& a : g.arrays) a.lambda = lambdas0[k++];
      for (size_t i = 0; i < pins_.size(); ++i) pins_[i].lambda = pin_lambda0[i];
      for (Collider& c : colliders_) {
        c.position = c.position_prev = c.frame_position;
        c.rotation = c.rotation_prev = c.frame_rotation;
      }
      warning_.frame = report_.frame;
      warning_.particle = bad;
      warning_.message = "non-finite position or velocity at particle " + std::to_string(bad) + " in frame " +
                         std::to_string(report_.frame) + "; the world was restored to the start of the frame";
      throw Error(ErrorCode::numerical, warning_.message);
    }
  }
  for (Pin& p : pins_)
    if (p.alive) p.target_prev = p.target;
  for (Collider& c : colliders_)
    if (c.alive) {
      c.frame_position = c.desc.position;
      c.frame_rotation = c.desc.rotation;
    }
  report_.frame += 1;
  report_.time += settings_.dt;
  measure();
}

}  // namespace embra
