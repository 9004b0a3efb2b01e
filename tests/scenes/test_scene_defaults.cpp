// The defaults and ranges the schemas and README.md state, against the code: nothing may drift.
//
//   test_scene_defaults schema SCHEMA_DIR
//     1. Every "default" in scene.schema.json and tolerances.schema.json equals what the C ABI gives
//        (the embra_default_* functions, which take them from the core's structs) and what the
//        scene loader fills in for a key left out (a minimal scene, loaded and saved); a default
//        with no check here fails, so a new one cannot go unchecked.
//     2. Every integer "minimum" and "maximum" of a solver, group or field setting is what the C
//        ABI enforces: the bound itself is accepted, one beyond it refused; and dt's bounds are
//        EMBRA_MIN_POSITIVE and EMBRA_MAX_DT, accepted, and refused just beyond.
//   test_scene_defaults readme README
//     The defaults README.md states in prose (substeps, tethers, dt, gravity) are the C ABI's.
#include "embra/embra.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using nlohmann::json;

namespace {

int g_passed = 0, g_failed = 0;

void check(bool ok, const std::string& what) {
  if (ok) {
    ++g_passed;
  } else {
    ++g_failed;
    std::fprintf(stderr, "FAILED: %s\n", what.c_str());
  }
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Calls `f(pointer, value)` for every "default" in `schema`.
void each_default(const json& schema, const std::string& at,
                  const std::function<void(const std::string&, const json&)>& f) {
  if (schema.is_array()) {
    for (size_t i = 0; i < schema.size(); ++i) each_default(schema[i], at + "/" + std::to_string(i), f);
    return;
  }
  if (!schema.is_object()) return;
  for (const auto& [key, value] : schema.items()) {
    if (key == "const" || key == "enum" || key == "examples" || key == "required") continue;
    if (key == "default")
      f(at, value);
    else
      each_default(value, at + "/" + key, f);
  }
}

/// Equal as JSON, numbers compared as doubles (600 and 600.0 are one value).
bool same_value(const json& a, const json& b) {
  if (a.is_number() && b.is_number()) return a.get<double>() == b.get<double>();
  if (a.is_array() && b.is_array()) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
      if (!same_value(a[i], b[i])) return false;
    return true;
  }
  return a == b;
}

json vec(const double* v, int n) {
  json out = json::array();
  for (int k = 0; k < n; ++k) out.push_back(v[k]);
  return out;
}

/// The group a C def names by default: {0,0} is the default group.
json group_name(embra_group_id id) {
  return id.index == 0 && id.generation == 0 ? json("default") : json("a group");
}

json generate_names(int32_t flags) {
  json out = json::array();
  const char* names[] = {"stretch", "shear", "bend", "volume"};
  for (int k = 0; k < 4; ++k)
    if (flags & (1 << k)) out.push_back(names[k]);
  return out;
}

json panel_pins_name(int32_t pins) {
  return pins == EMBRA_PANEL_PINS_NONE          ? "none"
         : pins == EMBRA_PANEL_PINS_TOP_CORNERS ? "top_corners"
                                                : "top_and_bottom_corners";
}

/// Whether a group the C ABI creates with the default def is enabled.
bool group_enabled() {
  embra_world* w = nullptr;
  embra_group_def def = embra_default_group_def();
  embra_group_id g{};
  int32_t enabled = -1;
  if (embra_world_create(&w, nullptr) != EMBRA_OK || embra_group_create(w, &def, &g) != EMBRA_OK ||
      embra_group_get_enabled(w, g, &enabled) != EMBRA_OK)
    throw std::runtime_error(std::string("a new group's enabled flag: ") + embra_last_error_message());
  embra_world_destroy(w);
  return enabled == 1;
}

/// A minimal scene holding one of each def with every optional key left out, as the loader
/// reads and saves it.
const char* const kMinimalScene = R"({
  "format": "embra-scene", "version": 1,
  "groups": [{"name": "g"}],
  "bodies": [{"name": "b", "mesh": {"generator": "icosphere", "radius": 1, "subdivisions": 0}}],
  "pins": [{"particle": 0}],
  "area_loads": [{"particles": [0, 1, 2], "pressure": 1}],
  "colliders": [{"shape": "capsule"}, {"shape": "box"}],
  "fields": [{"type": "wind"}, {"type": "pressure", "body": "b"}, {"type": "surface_tension", "body": "b"},
             {"type": "vortex"}]
})";

json saved_minimal_scene(int64_t& frames) {
  embra_world* w = nullptr;
  if (embra_world_load_json(&w, kMinimalScene, static_cast<int64_t>(std::strlen(kMinimalScene)), ".") != EMBRA_OK)
    throw std::runtime_error(std::string("the minimal scene does not load: ") + embra_last_error_message());
  int64_t n = 0;
  embra_world_save_json(w, nullptr, 0, &n);
  std::string text(static_cast<size_t>(n), '\0');
  embra_world_save_json(w, text.data(), n, &n);
  embra_world_get_scene_frames(w, &frames);
  embra_world_destroy(w);
  return json::parse(text.c_str());
}

/// What the code says for each schema default, by the default's pointer: the C ABI's value first,
/// then (when the loader fills it in for a scene that leaves it out) the loaded scene's.
std::map<std::string, std::vector<json>> code_defaults() {
  std::map<std::string, std::vector<json>> c;
  const std::string d = "scene#/definitions/";
  int64_t frames = 0;
  const json saved = saved_minimal_scene(frames);
  const json& fields = saved["fields"];
  c["scene#/properties/frames"] = {frames};

  const embra_solver_def s = embra_default_solver_def();
  const std::map<std::string, json> solver = {{"dt", s.dt},
                                              {"substeps", s.substeps},
                                              {"iterations", s.iterations},
                                              {"gravity", vec(s.gravity, 3)},
                                              {"damping", s.damping},
                                              {"settle_speed", s.settle_speed},
                                              {"realign_passes", s.realign_passes},
                                              {"chebyshev_rho_milli", s.chebyshev_rho_milli},
                                              {"tethers", s.tethers},
                                              {"self_collision", s.self_collision},
                                              {"chain_solve", s.chain_solve},
                                              {"threads", s.threads},
                                              {"global_solve", s.global_solve}};
  for (const auto& [key, value] : solver) c[d + "solver/properties/" + key] = {value, saved["solver"][key]};

  const embra_group_def g = embra_default_group_def();
  c[d + "group/properties/order"] = {g.order, saved["groups"][2]["order"]};
  c[d + "group/properties/weight"] = {g.weight, saved["groups"][2]["weight"]};
  c[d + "group/properties/enabled"] = {group_enabled(), saved["groups"][2]["enabled"]};

  const embra_material m = embra_default_material();
  const std::map<std::string, json> material = {{"mass", m.mass},
                                                {"density", m.density},
                                                {"stretch_compliance", m.stretch_compliance},
                                                {"shear_compliance", m.shear_compliance},
                                                {"bend_compliance", m.bend_compliance},
                                                {"volume_compliance", m.volume_compliance},
                                                {"damping", m.damping},
                                                {"thickness", m.thickness},
                                                {"friction_static", m.friction_static},
                                                {"friction_dynamic", m.friction_dynamic}};
  for (const auto& [key, value] : material)
    c[d + "material/properties/" + key] = {value, saved["bodies"][0]["material"][key]};

  // A mesh without origin, rotation or scale stays where and as large as it is given.
  for (const char* mesh :
       {"grid_mesh", "triangle_mesh", "icosphere_mesh", "rounded_box_mesh", "tube_mesh", "obj_mesh"}) {
    c[d + mesh + "/properties/origin"] = {json::array({0, 0, 0})};
    c[d + mesh + "/properties/rotation"] = {json::array({1, 0, 0, 0})};
  }
  c[d + "obj_mesh/properties/scale"] = {1};
  c[d + "rounded_box_mesh/properties/radius"] = {0};  // a sharp box

  const embra_body_def b = embra_default_body_def();
  c[d + "body/properties/generate"] = {generate_names(b.generate), saved["bodies"][0]["generate"]};
  c[d + "body/properties/stretch_group"] = {group_name(b.stretch_group), saved["bodies"][0]["stretch_group"]};
  c[d + "body/properties/shear_group"] = {group_name(b.shear_group), saved["bodies"][0]["shear_group"]};
  c[d + "body/properties/bend_group"] = {group_name(b.bend_group), saved["bodies"][0]["bend_group"]};
  c[d + "body/properties/volume_group"] = {group_name(b.volume_group), saved["bodies"][0]["volume_group"]};
  c[d + "body/properties/rest_scale"] = {saved["bodies"][0]["rest_scale"]};

  const embra_panel_mesh_def p = embra_default_panel_mesh_def();
  const std::string pm = d + "panel_mesh/then/properties/";
  c[pm + "origin"] = {vec(p.origin, 3)};
  c[pm + "scale"] = {1};
  c[pm + "thickness"] = {p.thickness};
  c[pm + "mass"] = {p.mass};
  c[pm + "density"] = {p.density};
  c[pm + "damping"] = {p.damping};
  c[pm + "friction_static"] = {p.friction_static};
  c[pm + "friction_dynamic"] = {p.friction_dynamic};
  c[pm + "slide_compliance"] = {p.slide_compliance};
  c[pm + "pins"] = {panel_pins_name(p.pins)};
  c[d + "panel_corners"] = {p.corners == EMBRA_PANEL_CORNERS_WELDED ? "welded" : "shared"};
  c[d + "panel_precision"] = {p.precision == EMBRA_PANEL_PRECISION_FULL ? "full" : "single"};
  c[pm + "group"] = {group_name(p.group)};

  // An area load's mode left out is a zeroed embra_area_load's (there is no default def).
  const embra_area_load zeroed{};
  c[d + "area_load/properties/mode"] = {json(zeroed.mode == EMBRA_AREA_LOAD_NORMAL ? "normal" : "?"),
                                        saved["area_loads"][0]["mode"]};

  const embra_constraint_def k = embra_default_constraint_def();
  c[d + "constraint_batch/properties/group"] = {group_name(k.group)};
  c[d + "constraint_batch/properties/rest"] = {k.rest_from_current == 1 ? json("current") : json(k.rest)};
  c[d + "constraint_batch/properties/compliance"] = {k.compliance};

  // A shape match's group left out is embra_shape_match_add's {0,0}: the default group.
  c[d + "shape_match/properties/group"] = {group_name(embra_group_id{0, 0})};

  const embra_pin_def pin = embra_default_pin_def();
  c[d + "pin/properties/compliance"] = {pin.compliance, saved["pins"][0]["compliance"]};
  c[d + "pin/properties/group"] = {group_name(pin.group)};
  // A scene's pin is embra_pin_create's point pin unless it names a support; then its axis defaults
  // to embra_support_def's.
  const embra_support_def support = embra_default_support_def();
  c[d + "pin/properties/support"] = {json("point")};
  c[d + "pin/properties/axis"] = {json::array({support.axis[0], support.axis[1], support.axis[2]})};
  c[d + "pin/properties/closed"] = {json(embra_default_polyline_support_def().closed == 1)};

  const embra_collider_def col = embra_default_collider_def();
  const json& capsule = saved["colliders"][0];
  const json& box = saved["colliders"][1];
  c[d + "collider/properties/position"] = {vec(col.position, 3), capsule["position"]};
  c[d + "collider/properties/rotation"] = {vec(col.rotation, 4), capsule["rotation"]};
  c[d + "collider/properties/radius"] = {col.radius, capsule["radius"]};
  c[d + "collider/properties/half_extents"] = {vec(col.half_extents, 3), box["half_extents"]};
  c[d + "collider/properties/half_length"] = {col.half_length, capsule["half_length"]};
  c[d + "collider/properties/thickness"] = {col.thickness, capsule["thickness"]};
  c[d + "collider/properties/friction_static"] = {col.friction_static, capsule["friction_static"]};
  c[d + "collider/properties/friction_dynamic"] = {col.friction_dynamic, capsule["friction_dynamic"]};

  const embra_wind_def wind = embra_default_wind_def();
  const std::string wf = d + "wind_field/properties/";
  c[wf + "direction"] = {vec(wind.direction, 3), fields[0]["direction"]};
  c[wf + "speed"] = {wind.speed, fields[0]["speed"]};
  c[wf + "air_density"] = {wind.air_density, fields[0]["air_density"]};
  c[wf + "drag"] = {wind.drag, fields[0]["drag"]};
  c[wf + "lift"] = {wind.lift, fields[0]["lift"]};

  const embra_pressure_def pr = embra_default_pressure_def();
  const std::string pf = d + "pressure_field/properties/";
  c[pf + "inside_pressure"] = {pr.inside_pressure, fields[1]["inside_pressure"]};
  c[pf + "outside_pressure"] = {pr.outside_pressure, fields[1]["outside_pressure"]};
  c[pf + "keep_volume"] = {pr.keep_volume, fields[1]["keep_volume"]};
  c[pf + "volume_compliance"] = {pr.volume_compliance, fields[1]["volume_compliance"]};
  c[pf + "rest_volume"] = {pr.rest_volume};  // 0: the volume enclosed at creation (saved as measured)

  const embra_surface_tension_def st = embra_default_surface_tension_def();
  const std::string sf = d + "surface_tension_field/properties/";
  c[sf + "tension"] = {st.tension, fields[2]["tension"]};
  c[sf + "regularisation"] = {st.regularisation, fields[2]["regularisation"]};

  const embra_vortex_def v = embra_default_vortex_def();
  const std::string vf = d + "vortex_field/properties/";
  c[vf + "center"] = {vec(v.center, 3), fields[3]["center"]};
  c[vf + "axis"] = {vec(v.axis, 3), fields[3]["axis"]};
  c[vf + "strength"] = {v.strength, fields[3]["strength"]};
  c[vf + "radius"] = {v.radius, fields[3]["radius"]};
  c[vf + "twist"] = {v.twist, fields[3]["twist"]};
  c[vf + "decay"] = {v.decay, fields[3]["decay"]};
  c[vf + "start_time"] = {v.start_time, fields[3]["start_time"]};

  const embra_tolerances t = embra_default_tolerances();
  c["tolerances#/properties/unit_scale"] = {t.unit_scale};
  return c;
}

void defaults(const std::string& dir) {
  std::map<std::string, json> stated;
  for (const auto& [name, file] : {std::pair{"scene", "scene.schema.json"}, {"tolerances", "tolerances.schema.json"}})
    each_default(json::parse(read_text(dir + "/" + file)), std::string(name) + "#",
                 [&](const std::string& at, const json& v) { stated[at] = v; });
  const auto code = code_defaults();
  for (const auto& [at, value] : stated) {
    const auto it = code.find(at);
    check(it != code.end(), at + ": the schema's default " + value.dump() + " has no check in test_scene_defaults");
    if (it == code.end()) continue;
    const char* source[] = {"the C ABI (embra_default_*)", "the loader (a scene leaving it out, saved)"};
    for (size_t i = 0; i < it->second.size(); ++i)
      check(same_value(value, it->second[i]), at + ": the schema's default is " + value.dump() + ", " +
                                                  (it->second.size() == 1 ? "the code's" : source[i]) + " " +
                                                  it->second[i].dump());
  }
  for (const auto& [at, values] : code) check(stated.count(at) == 1, at + ": the schema states no default");
  std::printf("%zu schema defaults checked\n", stated.size());
}

/// Whether a world with the default solver def changed by `edit` is accepted.
bool solver_accepts(const std::function<void(embra_solver_def&)>& edit) {
  embra_solver_def s = embra_default_solver_def();
  edit(s);
  embra_world* w = nullptr;
  const embra_status status = embra_world_create(&w, &s);
  embra_world_destroy(w);
  return status == EMBRA_OK;
}

/// The integer range [lo, hi] the schema gives `at`, against what `accepts(value)` says.
void same_range(const json& schema, const std::string& at, const std::function<bool(int64_t)>& accepts) {
  const json& p = schema.at(json::json_pointer(at));
  const int64_t lo = p.at("minimum").get<int64_t>(), hi = p.at("maximum").get<int64_t>();
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  check(accepts(lo), at + ": the schema's minimum " + std::to_string(lo) + " is refused by the C ABI");
  check(!accepts(lo - 1),
        at + ": " + std::to_string(lo - 1) + ", below the schema's " + range + ", is accepted by the C ABI");
  check(accepts(hi), at + ": the schema's maximum " + std::to_string(hi) + " is refused by the C ABI");
  check(!accepts(hi + 1),
        at + ": " + std::to_string(hi + 1) + ", above the schema's " + range + ", is accepted by the C ABI");
}

/// A closed tetrahedron's surface, for the fields that need a closed body.
embra_body_id tetrahedron(embra_world* w) {
  static const double x[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  static const int32_t t[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
  embra_body_def b = embra_default_body_def();
  b.vertex_count = 4;
  b.positions = x;
  b.triangle_count = 4;
  b.triangles = t;
  embra_body_id id{};
  if (embra_body_create(w, &b, &id, nullptr) != EMBRA_OK)
    throw std::runtime_error(std::string("tetrahedron: ") + embra_last_error_message());
  return id;
}

void ranges(const std::string& dir) {
  const json scene = json::parse(read_text(dir + "/scene.schema.json"));
  const std::string sp = "/definitions/solver/properties/";
  const std::map<std::string, int32_t embra_solver_def::*> solver = {
      {"substeps", &embra_solver_def::substeps},
      {"iterations", &embra_solver_def::iterations},
      {"realign_passes", &embra_solver_def::realign_passes},
      {"chebyshev_rho_milli", &embra_solver_def::chebyshev_rho_milli},
      {"tethers", &embra_solver_def::tethers},
      {"self_collision", &embra_solver_def::self_collision},
      {"chain_solve", &embra_solver_def::chain_solve},
      {"threads", &embra_solver_def::threads},
      {"global_solve", &embra_solver_def::global_solve}};
  for (const auto& [key, member] : solver)
    same_range(scene, sp + key, [&, member = member](int64_t v) {
      return v >= INT32_MIN && v <= INT32_MAX && solver_accepts([&](embra_solver_def& s) {
               s.substeps = s.iterations = 1;  // so that substeps x iterations stays in bounds
               s.*member = static_cast<int32_t>(v);
             });
    });
  // Every integer setting with bounds in the solver's schema is in the list above.
  for (const auto& [key, p] : scene.at(json::json_pointer("/definitions/solver/properties")).items())
    if (p.contains("minimum") && p.value("type", "") == "integer")
      check(solver.count(key) == 1,
            sp + key + ": a bounded integer setting with no range check in test_scene_defaults");
  const auto dt_accepted = [](double dt) { return solver_accepts([&](embra_solver_def& s) { s.dt = dt; }); };
  check(scene.at(json::json_pointer(sp + "dt/minimum")).get<double>() == EMBRA_MIN_POSITIVE,
        "dt minimum is EMBRA_MIN_POSITIVE");
  check(scene.at(json::json_pointer(sp + "dt/maximum")).get<double>() == EMBRA_MAX_DT, "dt maximum is EMBRA_MAX_DT");
  check(dt_accepted(EMBRA_MIN_POSITIVE) && !dt_accepted(std::nextafter(EMBRA_MIN_POSITIVE, 0.0)),
        "the C ABI accepts dt from EMBRA_MIN_POSITIVE, not below");
  check(dt_accepted(EMBRA_MAX_DT) && !dt_accepted(std::nextafter(EMBRA_MAX_DT, 2 * EMBRA_MAX_DT)),
        "the C ABI accepts dt up to EMBRA_MAX_DT, not above");

  const auto in_world = [](const std::function<embra_status(embra_world*)>& f) {
    embra_world* w = nullptr;
    embra_world_create(&w, nullptr);
    const embra_status status = f(w);
    embra_world_destroy(w);
    return status == EMBRA_OK;
  };
  for (const char* key : {"order", "weight"})
    same_range(scene, std::string("/definitions/group/properties/") + key, [&](int64_t v) {
      if (v < INT32_MIN || v > INT32_MAX) return false;
      return in_world([&](embra_world* w) {
        embra_group_def g = embra_default_group_def();
        (key == std::string("order") ? g.order : g.weight) = static_cast<int32_t>(v);
        embra_group_id id{};
        return embra_group_create(w, &g, &id);
      });
    });
  same_range(scene, "/definitions/pressure_field/properties/keep_volume", [&](int64_t v) {
    return in_world([&](embra_world* w) {
      embra_pressure_def p = embra_default_pressure_def();
      p.body = tetrahedron(w);
      p.keep_volume = static_cast<int32_t>(v);
      embra_field_id id{};
      return embra_pressure_create(w, &p, &id);
    });
  });
}

/// Every number README.md gives as a default (in the phrasings it uses) is the C ABI's.
void readme(const std::string& path) {
  const std::string text = read_text(path);
  const embra_solver_def s = embra_default_solver_def();
  int found = 0;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    if (line.find("default") == std::string::npos) continue;
    const std::string at = "README.md:" + std::to_string(number) + ": ";
    std::smatch m;
    for (const std::regex& re :
         {std::regex(R"(each substep \((\d+) by default\))"), std::regex(R"(defaults:[^#/]*?(\d+) substeps)")})
      for (auto it = std::sregex_iterator(line.begin(), line.end(), re); it != std::sregex_iterator(); ++it, ++found)
        check(std::stoi((*it)[1]) == s.substeps,
              at + "says " + (*it)[1].str() + " substeps by default, the code " + std::to_string(s.substeps));
    const std::regex tethers(R"(`tethers`, (\d+) by default)");
    for (auto it = std::sregex_iterator(line.begin(), line.end(), tethers); it != std::sregex_iterator(); ++it, ++found)
      check(std::stoi((*it)[1]) == s.tethers,
            at + "says " + (*it)[1].str() + " tethers by default, the code " + std::to_string(s.tethers));
    const std::regex dt(R"(defaults: dt 1/(\d+) s)");
    for (auto it = std::sregex_iterator(line.begin(), line.end(), dt); it != std::sregex_iterator(); ++it, ++found)
      check(1.0 / std::stoi((*it)[1]) == s.dt,
            at + "says dt 1/" + (*it)[1].str() + " s by default, the code " + json(s.dt).dump());
    if (line.find("defaults:") != std::string::npos && line.find("gravity -z") != std::string::npos) {
      ++found;
      check(s.gravity[0] == 0.0 && s.gravity[1] == 0.0 && s.gravity[2] < 0.0,
            at + "says gravity -z by default, the code " + vec(s.gravity, 3).dump());
    }
  }
  check(found >= 4, "README.md states the default substeps, tethers, dt and gravity (found " + std::to_string(found) +
                        " statements)");
  std::printf("%d default statements in README.md checked\n", found);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc == 3 ? argv[1] : "";
  if (mode != "schema" && mode != "readme") {
    std::fprintf(stderr, "usage: test_scene_defaults schema SCHEMA_DIR | readme README\n");
    return 2;
  }
  try {
    if (mode == "schema") {
      defaults(argv[2]);
      ranges(argv[2]);
    } else {
      readme(argv[2]);
    }
  } catch (const std::exception& e) {
    check(false, std::string("exception: ") + e.what());
  }
  std::printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
