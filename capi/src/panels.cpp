// Panel meshes: creation, fabrication metrics against tolerances, cut lists.
#include "copy.hpp"
#include "guard.hpp"

#include "embra/core/limits.hpp"
#include "embra/core/panels.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

using namespace embra::capi;

// The C values cast to core enums here are pinned to them in enum_pins_generated.hpp.

namespace {
constexpr std::tuple kPanelMeshCopies{
    Copy{&embra_panel_mesh_def::thickness, &embra::PanelMeshDesc::thickness},
    Copy{&embra_panel_mesh_def::mass, &embra::PanelMeshDesc::mass},
    Copy{&embra_panel_mesh_def::density, &embra::PanelMeshDesc::density},
    Copy{&embra_panel_mesh_def::damping, &embra::PanelMeshDesc::damping},
    Copy{&embra_panel_mesh_def::friction_static, &embra::PanelMeshDesc::friction_static},
    Copy{&embra_panel_mesh_def::friction_dynamic, &embra::PanelMeshDesc::friction_dynamic},
    Copy{&embra_panel_mesh_def::slide_compliance, &embra::PanelMeshDesc::slide_compliance}};
}  // namespace

extern "C" {

embra_panel_mesh_def embra_default_panel_mesh_def(void) {
  embra_panel_mesh_def d{};
  d.version = EMBRA_PANEL_MESH_DEF_VERSION;
  d.grid_columns = 4;
  d.grid_rows = 4;
  d.panel_size = 0.8;
  const embra::PanelMeshDesc p;
  d.pins = static_cast<int32_t>(p.pins);
  d.corners = static_cast<int32_t>(p.corners);
  d.precision = static_cast<int32_t>(p.precision);
  to_c(kPanelMeshCopies, p, d);
  return d;
}

embra_status embra_panel_mesh_create(embra_world* world, const embra_panel_mesh_def* def, embra_body_id* out_body,
                                     int32_t* out_first_particle) {
  return guard("embra_panel_mesh_create", world, [&] {
    need(def, "def");
    need(out_body, "out_body");
    need_version(def->version, EMBRA_PANEL_MESH_DEF_VERSION, "embra_panel_mesh_def");
    need_count(def->vertex_count, "def.vertex_count");
    std::vector<double> grid_positions;
    std::vector<int32_t> grid_quads;
    embra::PanelMeshDesc d;
    if (def->vertex_count == 0) {
      if (def->quad_count != 0)
        refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.quad_count must be 0 for a grid (vertex_count 0)");
      embra::panel_grid(def->grid_columns, def->grid_rows, def->panel_size,
                        embra::Vec3(def->origin[0], def->origin[1], def->origin[2]), grid_positions, grid_quads);
      d.positions = grid_positions;
      d.quads = grid_quads;
    } else {
      if (def->quad_count <= 0) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "def.quad_count must be > 0");
      d.positions = view(def->positions, 3 * static_cast<int64_t>(def->vertex_count), "def.positions");
      d.quads = view(def->quads, 4 * static_cast<int64_t>(def->quad_count), "def.quads");
    }
    to_core(kPanelMeshCopies, *def, d);
    d.pins = static_cast<embra::PanelPins>(def->pins);
    d.corners = static_cast<embra::PanelCorners>(def->corners);        // checked by build_panel_mesh
    d.precision = static_cast<embra::PanelPrecision>(def->precision);  // checked by build_panel_mesh
    d.group = to_id(def->group);
    d.tolerances = embra::io::parse_tolerances(world->meta.tolerances);  // the world's, in force
    const embra::Id id = embra::build_panel_mesh(world->world, d);
    *out_body = from_id<embra_body_id>(id);
    if (out_first_particle) *out_first_particle = world->world.body(id).first_particle;
  });
}

}  // extern "C"

namespace {

const embra::PanelLayout& layout_of(const embra_world* world, embra_body_id body) {
  world->world.body(to_id(body));  // stale ids: EMBRA_ERROR_STALE_ID
  const embra::PanelLayout* l = world->world.panel_layout(to_id(body));
  if (l == nullptr) refuse(EMBRA_ERROR_INVALID_ARGUMENT, "the body is not a panel mesh");
  return *l;
}

/// measure_panels of the body's layout at the world's positions, or the last one while neither has
/// changed (embra_world::panel_measure).
const embra::PanelErrors& measured(const embra_world* world, embra_body_id body) {
  const embra::PanelLayout& l = layout_of(world, body);
  const std::vector<embra::Vec3>& x = world->world.positions();
  const auto first = x.begin() + l.first_particle;
  const auto last = first + static_cast<std::ptrdiff_t>(l.particle_count());
  embra_world::PanelMeasure& m = world->panel_measure;
  const bool same = m.valid && m.body == to_id(body) && m.layout == &l &&
                    std::equal(first, last, m.x.begin(), m.x.end(), [](const embra::Vec3& a, const embra::Vec3& b) {
                      return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0;
                    });
  if (!same) {
    m.valid = false;
    m.errors = embra::measure_panels(l, x);
    m.x.assign(first, last);
    m.body = to_id(body);
    m.layout = &l;
    m.valid = true;
  }
  return m.errors;
}

constexpr std::tuple kTolerancesCopies{
    Copy{&embra_tolerances::unit_scale, &embra::Tolerances::unit_scale},
    Copy{&embra_tolerances::planarity, &embra::Tolerances::planarity},
    Copy{&embra_tolerances::planarity_distance, &embra::Tolerances::planarity_distance},
    Copy{&embra_tolerances::thickness, &embra::Tolerances::thickness},
    Copy{&embra_tolerances::miter, &embra::Tolerances::miter}};

embra::Tolerances to_tolerances(const embra_tolerances& t) {
  embra::Tolerances o;
  to_core(kTolerancesCopies, t, o);
  return o;
}

embra_tolerances from_tolerances(const embra::Tolerances& t) {
  embra_tolerances o{};
  o.version = EMBRA_TOLERANCES_VERSION;
  to_c(kTolerancesCopies, t, o);
  return o;
}

void check_tolerances(const embra_tolerances& t) {
  need_version(t.version, EMBRA_TOLERANCES_VERSION, "embra_tolerances");
  if (!(t.unit_scale >= embra::limits::kMinPositive && t.unit_scale <= embra::limits::kMaxUnitScale))
    refuse(EMBRA_ERROR_INVALID_ARGUMENT, "tolerances.unit_scale must be in [1e-300, 1e12]");
  const std::pair<const char*, embra_tolerance> all[] = {{"planarity", t.planarity},
                                                         {"planarity_distance", t.planarity_distance},
                                                         {"thickness", t.thickness},
                                                         {"miter", t.miter}};
  for (const auto& [name, v] : all) {
    if (!(v.target >= 0.0 && v.target <= embra::limits::kMaxAbsValue && v.max >= 0.0 &&
          v.max <= embra::limits::kMaxAbsValue))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string("tolerances.") + name + " must be finite and in [0, 1e300]");
    if (v.target > v.max)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string("tolerances.") + name + ".target is above its max");
  }
}

embra_metric_summary from_summary(const embra::MetricSummary& m) {
  return embra_metric_summary{m.max, m.rms, m.count, m.within_target, m.within_max, m.above_max};
}

}  // namespace

extern "C" {

embra_status embra_panel_mesh_get_panel_count(const embra_world* world, embra_body_id body, int32_t* out_count) {
  return guard("embra_panel_mesh_get_panel_count", world, [&] {
    need(out_count, "out_count");
    *out_count = layout_of(world, body).panel_count();
  });
}

embra_status embra_panel_mesh_get_corner_particles(const embra_world* world, embra_body_id body, int32_t* out,
                                                   int64_t capacity, int64_t* out_count) {
  return guard("embra_panel_mesh_get_corner_particles", world, [&] {
    need(out_count, "out_count");
    const embra::PanelLayout& l = layout_of(world, body);
    const int64_t n = 8 * static_cast<int64_t>(l.panel_count());
    if (fits(out, capacity, n, "values"))
      for (int32_t p = 0; p < l.panel_count(); ++p)
        for (int k = 0; k < 4; ++k) {
          out[8 * static_cast<int64_t>(p) + k] = l.top(p, k);
          out[8 * static_cast<int64_t>(p) + 4 + k] = l.bottom(p, k);
        }
    *out_count = n;
  });
}

embra_tolerances embra_default_tolerances(void) {
  return from_tolerances(embra::Tolerances{});
}

embra_status embra_world_get_tolerances(const embra_world* world, embra_tolerances* out_tolerances) {
  return guard("embra_world_get_tolerances", world, [&] {
    need(out_tolerances, "out_tolerances");
    *out_tolerances = from_tolerances(embra::io::parse_tolerances(world->meta.tolerances));
  });
}

embra_status embra_world_set_tolerances(embra_world* world, const embra_tolerances* tolerances) {
  return guard("embra_world_set_tolerances", world, [&] {
    need(tolerances, "tolerances");
    check_tolerances(*tolerances);
    world->meta.tolerances = embra::io::tolerances_json(to_tolerances(*tolerances));
  });
}

embra_status embra_panel_mesh_get_metrics(const embra_world* world, embra_body_id body,
                                          const embra_tolerances* tolerances, embra_panel_metrics* out_metrics) {
  return guard("embra_panel_mesh_get_metrics", world, [&] {
    need(out_metrics, "out_metrics");
    layout_of(world, body);  // the body refused before the tolerances
    embra::Tolerances t;
    if (tolerances) {
      check_tolerances(*tolerances);
      t = to_tolerances(*tolerances);
    } else {
      t = embra::io::parse_tolerances(world->meta.tolerances);
    }
    const embra::PanelReport r = embra::report_panels(measured(world, body), t);
    embra_panel_metrics m{};
    m.version = EMBRA_PANEL_METRICS_VERSION;
    m.within_tolerance = r.within_tolerance ? 1 : 0;
    m.planarity_top = from_summary(r.planarity_top);
    m.planarity_bottom = from_summary(r.planarity_bottom);
    m.corner_distance_top = from_summary(r.corner_distance_top);
    m.corner_distance_bottom = from_summary(r.corner_distance_bottom);
    m.diagonal_top = from_summary(r.diagonal_top);
    m.diagonal_bottom = from_summary(r.diagonal_bottom);
    m.thickness = from_summary(r.thickness);
    m.miter = from_summary(r.miter);
    m.conical = from_summary(r.conical);
    *out_metrics = m;
  });
}

embra_status embra_panel_mesh_get_corner_gap(const embra_world* world, embra_body_id body,
                                             embra_metric_summary* out_summary) {
  return guard("embra_panel_mesh_get_corner_gap", world, [&] {
    need(out_summary, "out_summary");
    const embra::PanelReport r = embra::report_panels(measured(world, body), {});
    *out_summary = from_summary(r.corner_gap);
  });
}

embra_status embra_panel_mesh_get_vertex_errors(const embra_world* world, embra_body_id body, int32_t metric,
                                                double* out, int64_t capacity, int64_t* out_count) {
  return guard("embra_panel_mesh_get_vertex_errors", world, [&] {
    need(out_count, "out_count");
    const embra::PanelLayout& l = layout_of(world, body);
    if (metric < 0 || metric >= embra::kPanelMetricCount)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "metric " + num(metric) + " is not an EMBRA_PANEL_METRIC_ value");
    const int64_t n = l.particle_count();
    if (!fits(out, capacity, n, "values")) {
      *out_count = n;
      return;
    }
    const std::vector<double> v =
        embra::vertex_errors(l, measured(world, body), static_cast<embra::PanelMetric>(metric));
    std::copy(v.begin(), v.end(), out);
    *out_count = n;
  });
}

embra_status embra_panel_mesh_export_cuts(const embra_world* world, embra_body_id body, int32_t format, char* out,
                                          int64_t capacity, int64_t* out_length) {
  return guard("embra_panel_mesh_export_cuts", world, [&] {
    need(out_length, "out_length");
    const embra::PanelLayout& l = layout_of(world, body);
    if (format != EMBRA_CUTS_JSON && format != EMBRA_CUTS_CSV)
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, "format must be EMBRA_CUTS_JSON or EMBRA_CUTS_CSV");
    const std::vector<embra::PanelCut> cuts = embra::panel_cuts(l, world->world.positions());
    write_text(format == EMBRA_CUTS_JSON ? embra::panel_cuts_json(cuts) : embra::panel_cuts_csv(cuts), out, capacity,
               out_length);
  });
}

}  // extern "C"
