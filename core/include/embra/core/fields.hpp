// Fields: forces and whole-body constraints that act on particles every substep, beside gravity.
//
//   wind             drag and lift on triangles from an air velocity (the flapping flag)
//   pressure         closed-surface air pressure p_in - p_out on a body's triangles, and optionally
//                    the body's enclosed volume held at a rest value (shrink wrap, balloons)
//   surface_tension  a soap-film material: a tension (N/m) on a body's area, with a tangential
//                    regularisation that keeps its triangles healthy without changing its shape
//   vortex           a volumetric torsion field about an axis, with a radial falloff, a strength
//                    varying along the axis and an exponential decay over time
//
// Forces are evaluated at the start of each substep from the positions and velocities there and
// change the velocities of movable particles (symplectic Euler, like gravity). The volume
// constraint is projected with XPBD (one multiplier per body) before the groups in every pass.
#pragma once

#include "embra/core/constraint_math.hpp"

#include <cstdint>
#include <vector>

namespace embra {

/// The numbering is part of the C ABI (embra_field_kind).
enum class FieldKind : int32_t { wind = 0, pressure = 1, surface_tension = 2, vortex = 3 };
constexpr int kFieldKindCount = 4;

struct WindDesc {
  Vec3 direction = Vec3(1.0, 0.0, 0.0);  // where the air goes (any length but not zero; used normalised)
  double speed = 0.0;                    // m/s, >= 0
  double air_density = 1.2;              // kg/m^3, >= 0
  double drag = 1.0;                     // drag coefficient (normal-plate model), >= 0
  double lift = 1.0;                     // lift coefficient, >= 0
};

struct PressureDesc {
  double inside_pressure = 0.0;    // Pa (N/m^2) on the inner side of the closed surface
  double outside_pressure = 0.0;   // Pa on the outer side; the net force per triangle is
                                   // (inside - outside) * area along the outward normal
  int32_t keep_volume = 0;         // 1: the enclosed volume is held at rest_volume (XPBD)
  double volume_compliance = 0.0;  // m^3/Pa (0 = incompressible); used with keep_volume
  double rest_volume = 0.0;        // m^3, > 0; 0 at creation = the volume enclosed then
};

struct SurfaceTensionDesc {
  double tension = 0.0;         // N/m, >= 0: the force is -tension * d(area)/dx
  double regularisation = 1.0;  // >= 0, dimensionless: a tangential umbrella force of
                                // regularisation * tension * (mean of neighbours - x), projected
                                // on the tangent plane, so it spaces vertices evenly and leaves the
                                // normal balance (the shape) to the tension alone
};

struct VortexDesc {
  Vec3 center = Vec3::Zero();
  Vec3 axis = Vec3(0.0, 0.0, 1.0);  // any length but not zero, used normalised; turns right-handed
  double strength = 0.0;            // m/s^2: tangential acceleration scale
  double radius = 1.0;              // m, > 0: a(x) = strength * S(t) * (1 + twist * s) *
                                    //   exp(-r^2 / radius^2) * (axis x d) / radius, where d is x's
                                    //   offset from the axis (r = |d|) and s its height along it
  double twist = 0.0;               // 1/m: how the strength varies along the axis (torsion)
  double decay = 0.0;               // 1/s, >= 0: S(t) = exp(-decay * (t - start_time))
  double start_time = 0.0;          // s of world time; the field acts from then on
};

struct FieldDesc {
  FieldKind kind = FieldKind::wind;
  int32_t body = -1;  // body index (Id::index); -1: wind and vortex act on every body, pressure and
                      // surface_tension need a body
  WindDesc wind;
  PressureDesc pressure;
  SurfaceTensionDesc surface_tension;
  VortexDesc vortex;
};

struct Field {
  FieldDesc desc;
  std::vector<int32_t> triangles;   // world particle indices the field acts on (wind, pressure, tension)
  std::vector<int32_t> particles;   // particles it acts on (vortex, tension)
  std::vector<int32_t> ring_start;  // tension: neighbours of particles[i] are ring[ring_start[i], ring_start[i+1])
  std::vector<int32_t> ring;
  double lambda = 0.0;  // volume multiplier of the current substep
  uint32_t generation = 0;
  bool alive = false;
};

/// The volume enclosed by a closed triangle surface (triangles wound outwards), m^3.
double enclosed_volume(const std::vector<Vec3>& x, const std::vector<int32_t>& triangles);

}  // namespace embra
