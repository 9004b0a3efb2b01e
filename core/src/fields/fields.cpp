// Fields (fields.hpp): wind, closed-surface pressure and volume, surface tension and the vortex.
// Creation validates everything before the world changes; the step calls apply_fields at the start
// of every substep (forces from the positions and velocities there) and project_volumes before the
// groups in every pass.
#include "embra/core/world.hpp"

#include "common/check.hpp"
#include "common/slots.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

namespace embra {

namespace {

void check_vec(const Vec3& v, const std::string& what) {
  for (int k = 0; k < 3; ++k) check_finite(v[k], what);
}

Vec3 unit_or_fail(const Vec3& v, const std::string& what) {
  check_vec(v, what);
  const double n = v.norm();
  if (!(n > 1e-12)) invalid(what + " must not be the zero vector");
  return v / n;
}

/// Whether every edge of the triangles is shared by exactly two of them, once in each direction
/// (a closed, consistently wound surface).
bool closed_and_oriented(const std::vector<int32_t>& tri) {
  std::map<std::pair<int32_t, int32_t>, int> directed;
  for (size_t t = 0; t + 2 < tri.size(); t += 3)
    for (int k = 0; k < 3; ++k) ++directed[{tri[t + k], tri[t + (k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    if (count != 1) return false;
    const auto back = directed.find({edge.second, edge.first});
    if (back == directed.end() || back->second != 1) return false;
  }
  return !directed.empty();
}

}  // namespace

double enclosed_volume(const std::vector<Vec3>& x, const std::vector<int32_t>& triangles) {
  double v = 0.0;
  for (size_t t = 0; t + 2 < triangles.size(); t += 3)
    v += x[triangles[t]].dot(x[triangles[t + 1]].cross(x[triangles[t + 2]]));
  return v / 6.0;
}

FieldDesc World::checked_field(const FieldDesc& desc) const {
  const int kind = static_cast<int>(desc.kind);
  if (kind < 0 || kind >= kFieldKindCount) invalid("unknown field kind " + std::to_string(kind));
  FieldDesc d = desc;
  const bool needs_body = d.kind == FieldKind::pressure || d.kind == FieldKind::surface_tension;
  if (d.body < -1 || d.body >= static_cast<int64_t>(bodies_.size()))
    invalid("field body " + std::to_string(d.body) + " does not name a body of this world");
  if (needs_body && d.body < 0) invalid("a pressure or surface tension field needs a body");
  const BodyInfo* b = d.body >= 0 ? &bodies_[d.body] : nullptr;
  if (b && d.kind != FieldKind::vortex && b->triangles.empty()) invalid("the field's body has no triangles");
  switch (d.kind) {
    case FieldKind::wind:
      unit_or_fail(d.wind.direction, "wind direction");  // kept as given (saved as given)
      check_non_negative(d.wind.speed, "wind speed");
      check_non_negative(d.wind.air_density, "wind air_density");
      check_non_negative(d.wind.drag, "wind drag");
      check_non_negative(d.wind.lift, "wind lift");
      break;
    case FieldKind::pressure: {
      check_finite(d.pressure.inside_pressure, "pressure inside_pressure");
      check_finite(d.pressure.outside_pressure, "pressure outside_pressure");
      if (d.pressure.keep_volume != 0 && d.pressure.keep_volume != 1) invalid("pressure keep_volume must be 0 or 1");
      check_non_negative(d.pressure.volume_compliance, "pressure volume_compliance");
      check_non_negative(d.pressure.rest_volume, "pressure rest_volume");
      if (!closed_and_oriented(b->triangles))
        invalid("a pressure field needs a closed body: every edge shared by two triangles wound the same way");
      // Winding is judged on the body's rest shape (a saved world may be loaded in any state).
      std::vector<Vec3> rest(x_.size(), Vec3::Zero());
      for (int32_t i = 0; i < b->particle_count; ++i) rest[b->first_particle + i] = b->rest_positions[i];
      if (!(enclosed_volume(rest, b->triangles) > 0.0))
        invalid(
            "the body encloses no positive volume (its triangles must wind outwards, counter-clockwise seen "
            "from outside)");
      if (d.pressure.rest_volume == 0.0) {
        const double volume = enclosed_volume(x_, b->triangles);
        if (!(volume > 0.0)) invalid("rest_volume is 0 and the body encloses no positive volume now");
        d.pressure.rest_volume = volume;
      }
      break;
    }
    case FieldKind::surface_tension:
      check_non_negative(d.surface_tension.tension, "surface tension");
      check_non_negative(d.surface_tension.regularisation, "surface tension regularisation");
      break;
    case FieldKind::vortex:
      check_vec(d.vortex.center, "vortex center");
      unit_or_fail(d.vortex.axis, "vortex axis");
      check_finite(d.vortex.strength, "vortex strength");
      check_positive(d.vortex.radius, "vortex radius");
      check_finite(d.vortex.twist, "vortex twist");
      check_non_negative(d.vortex.decay, "vortex decay");
      check_finite(d.vortex.start_time, "vortex start_time");
      break;
  }
  return d;
}

Id World::create_field(const FieldDesc& desc) {
  const FieldDesc d = checked_field(desc);
  const BodyInfo* b = d.body >= 0 ? &bodies_[d.body] : nullptr;
  // Everything is valid: build and store.
  Field f;
  f.desc = d;
  if (b) {
    f.triangles = b->triangles;
    for (int32_t i = 0; i < b->particle_count; ++i) f.particles.push_back(b->first_particle + i);
  }
  if (d.kind == FieldKind::surface_tension) {
    std::vector<std::vector<int32_t>> nb(static_cast<size_t>(b->particle_count));
    for (size_t e = 0; e + 1 < b->edges.size(); e += 2) {
      const int32_t p = b->edges[e] - b->first_particle, q = b->edges[e + 1] - b->first_particle;
      nb[p].push_back(b->edges[e + 1]);
      nb[q].push_back(b->edges[e]);
    }
    f.ring_start.push_back(0);
    for (auto& r : nb) {
      std::sort(r.begin(), r.end());
      f.ring.insert(f.ring.end(), r.begin(), r.end());
      f.ring_start.push_back(static_cast<int32_t>(f.ring.size()));
    }
  }
  return slots::create(fields_, std::move(f));
}

const Field& World::field(Id id) const {
  const Field* f = slots::find(fields_, id);
  if (f == nullptr) throw Error(ErrorCode::stale_id, "field id does not name a live field of this world");
  return *f;
}

void World::set_field(Id id, const FieldDesc& desc) {
  const Field& f = field(id);
  if (desc.kind != f.desc.kind || desc.body != f.desc.body)
    invalid("a field keeps the kind and body it was created with; destroy it and create another");
  const FieldDesc d = checked_field(desc);
  fields_[id.index].desc = d;
}

void World::destroy_field(Id id) {
  field(id);
  slots::destroy(fields_, id);
}

size_t World::field_count() const {
  return slots::live_count(fields_);
}

void World::apply_fields(double h, double time) {
  bool any = false;
  for (Field& f : fields_)
    if (f.alive) {
      any = true;
      f.lambda = 0.0;
    }
  if (!any) return;
  std::vector<Vec3>& force = field_force_;
  force.assign(x_.size(), Vec3::Zero());
  std::vector<Vec3> normal;  // surface tension: area-weighted vertex normals
  for (const Field& f : fields_) {
    if (!f.alive) continue;
    const FieldDesc& d = f.desc;
    if (d.kind == FieldKind::wind) {
      const Vec3 air = d.wind.speed * d.wind.direction.normalized();
      auto triangles = [&](const std::vector<int32_t>& tri) {
        for (size_t t = 0; t + 2 < tri.size(); t += 3) {
          const int32_t a = tri[t], b = tri[t + 1], c = tri[t + 2];
          const Vec3 an = 0.5 * (x_[b] - x_[a]).cross(x_[c] - x_[a]);
          const double area = an.norm();
          if (!(area > 0.0)) continue;
          const Vec3 n = an / area;
          const Vec3 rel = air - (v_[a] + v_[b] + v_[c]) / 3.0;  // air velocity relative to the triangle
          const double speed = rel.norm();
          if (!(speed > 0.0)) continue;
          const Vec3 u = rel / speed;
          const double cos_n = u.dot(n);
          const double q = 0.5 * d.wind.air_density * speed * speed * area;
          // Drag along the relative air flow, in proportion to the area facing it; lift across the
          // flow, the part of a flat plate's normal pressure force perpendicular to it.
          const Vec3 F = q * (d.wind.drag * std::abs(cos_n) * u + d.wind.lift * cos_n * (n - cos_n * u));
          const Vec3 third = F / 3.0;
          force[a] += third;
          force[b] += third;
          force[c] += third;
        }
      };
      if (d.body >= 0)
        triangles(f.triangles);
      else
        for (const BodyInfo& b : bodies_) triangles(b.triangles);
    } else if (d.kind == FieldKind::pressure) {
      const double dp = d.pressure.inside_pressure - d.pressure.outside_pressure;
      if (dp == 0.0) continue;
      const std::vector<int32_t>& tri = f.triangles;
      for (size_t t = 0; t + 2 < tri.size(); t += 3) {
        const int32_t a = tri[t], b = tri[t + 1], c = tri[t + 2];
        const Vec3 third = (dp / 6.0) * (x_[b] - x_[a]).cross(x_[c] - x_[a]);  // dp * area vector / 3
        force[a] += third;
        force[b] += third;
        force[c] += third;
      }
    } else if (d.kind == FieldKind::surface_tension) {
      const double gamma = d.surface_tension.tension;
      const int32_t first = f.particles.empty() ? 0 : f.particles.front();
      normal.assign(f.particles.size(), Vec3::Zero());
      const std::vector<int32_t>& tri = f.triangles;
      for (size_t t = 0; t + 2 < tri.size(); t += 3) {
        const int32_t a = tri[t], b = tri[t + 1], c = tri[t + 2];
        const Vec3 an = 0.5 * (x_[b] - x_[a]).cross(x_[c] - x_[a]);
        const double area = an.norm();
        if (!(area > 0.0)) continue;
        const Vec3 n = an / area;
        // d(area)/dx_k = n x (opposite edge) / 2, the edge taken counter-clockwise.
        force[a] -= (0.5 * gamma) * n.cross(x_[c] - x_[b]);
        force[b] -= (0.5 * gamma) * n.cross(x_[a] - x_[c]);
        force[c] -= (0.5 * gamma) * n.cross(x_[b] - x_[a]);
        normal[a - first] += an;
        normal[b - first] += an;
        normal[c - first] += an;
      }
      const double k = d.surface_tension.regularisation * gamma;
      if (k == 0.0) continue;
      for (size_t i = 0; i < f.particles.size(); ++i) {
        const int32_t p = f.particles[i];
        const int32_t lo = f.ring_start[i], hi = f.ring_start[i + 1];
        if (hi == lo) continue;
        Vec3 mean = Vec3::Zero();
        for (int32_t r = lo; r < hi; ++r) mean += x_[f.ring[r]];
        Vec3 l = mean / static_cast<double>(hi - lo) - x_[p];
        const double nn = normal[i].norm();
        if (nn > 0.0) {
          const Vec3 nu = normal[i] / nn;
          l -= l.dot(nu) * nu;
        }
        force[p] += k * l;
      }
    } else {  // vortex: an acceleration
      const double age = time - d.vortex.start_time;
      if (age < 0.0) continue;
      const double s_t = d.vortex.strength * std::exp(-d.vortex.decay * age);
      const double inv_r2 = 1.0 / (d.vortex.radius * d.vortex.radius);
      const Vec3 axis = d.vortex.axis.normalized();
      auto accelerate = [&](int32_t p) {
        if (w_[p] == 0.0) return;
        const Vec3 off = x_[p] - d.vortex.center;
        const double s = off.dot(axis);
        const Vec3 perp = off - s * axis;
        const double g = s_t * (1.0 + d.vortex.twist * s) * std::exp(-perp.squaredNorm() * inv_r2) / d.vortex.radius;
        v_[p] += (h * g) * axis.cross(perp);
      };
      if (d.body >= 0)
        for (int32_t p : f.particles) accelerate(p);
      else
        for (int32_t p = 0; p < particle_count(); ++p) accelerate(p);
    }
  }
  for (size_t i = 0; i < x_.size(); ++i)
    if (w_[i] != 0.0) v_[i] += (h * w_[i]) * force[i];
}

void World::project_volumes(double h) {
  const double inv_h2 = 1.0 / (h * h);
  std::vector<Vec3>& grad = field_force_;  // free during the projections
  for (Field& f : fields_) {
    if (!f.alive || f.desc.kind != FieldKind::pressure || f.desc.pressure.keep_volume == 0) continue;
    const std::vector<int32_t>& tri = f.triangles;
    const int32_t first = f.particles.front();
    grad.assign(f.particles.size(), Vec3::Zero());
    double volume = 0.0;
    for (size_t t = 0; t + 2 < tri.size(); t += 3) {
      const int32_t a = tri[t], b = tri[t + 1], c = tri[t + 2];
      volume += x_[a].dot(x_[b].cross(x_[c]));
      grad[a - first] += x_[b].cross(x_[c]);
      grad[b - first] += x_[c].cross(x_[a]);
      grad[c - first] += x_[a].cross(x_[b]);
    }
    volume /= 6.0;
    const double alpha = f.desc.pressure.volume_compliance * inv_h2;
    double denom = alpha;
    for (size_t i = 0; i < f.particles.size(); ++i) {
      grad[i] /= 6.0;
      denom += w_[f.particles[i]] * grad[i].squaredNorm();
    }
    if (!(denom > 0.0)) continue;
    const double dl = (-(volume - f.desc.pressure.rest_volume) - alpha * f.lambda) / denom;
    f.lambda += dl;
    for (size_t i = 0; i < f.particles.size(); ++i) x_[f.particles[i]] += (w_[f.particles[i]] * dl) * grad[i];
  }
}

}  // namespace embra
