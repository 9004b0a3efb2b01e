// JSON scenes: the second door to the same world. A scene document is validated against
// schemas/scene.schema.json first (valijson), then built through the same embra::World calls a C
// host makes; saving writes the complete world (rest shapes, constraints, pins, colliders,
// actions and the current state) so that loading it again gives the same world, bit for bit.
#pragma once

#include "embra/core/panels.hpp"
#include "embra/core/world.hpp"

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace embra::io {

/// A scene document that cannot be read or built. The message starts with the JSON pointer of the
/// offending value ("/bodies/0/material/mass: ...").
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A value that changes over frames: linear between keys, held before the first and after the last.
struct Action {
  enum class Type : int32_t { rest_scale, pin_target, collider_pose, gravity };
  Type type = Type::gravity;
  Id target;  // body, pin or collider
  std::vector<int64_t> frames;
  std::vector<std::vector<double>> values;
};

/// What a scene holds beyond the world itself.
struct SceneMeta {
  std::string name;
  std::string description;
  int64_t frames = 600;
  std::map<uint32_t, std::string> group_names;  // by slot index
  std::map<uint32_t, std::string> body_names;
  std::map<uint32_t, std::string> pin_names;
  std::map<uint32_t, std::string> collider_names;
  std::vector<Action> actions;
  std::string tolerances;                       // the tolerance document as JSON text, "" if none
  std::map<uint32_t, std::string> field_names;  // by field slot (fields without a name are not listed)
};

/// How a scene may reach outside its own text.
struct LoadOptions {
  std::string base_dir = ".";             // relative OBJ paths resolve here
  bool allow_paths_outside_base = false;  // true: OBJ paths may be absolute or lead out of base_dir
};
/// Parses, validates and builds a scene. Throws SceneError; nothing is returned on failure.
std::unique_ptr<World> load_scene(std::string_view text, const LoadOptions& options, SceneMeta& out_meta);
/// load_scene with OBJ paths confined to `base_dir`.
std::unique_ptr<World> load_scene(std::string_view text, const std::string& base_dir, SceneMeta& out_meta);

/// Writes the complete world and its meta as a scene document (floats round-trip exactly).
std::string save_scene(const World& world, const SceneMeta& meta);

/// Applies the actions' values for `frame` (the frame the next step produces).
void apply_actions(World& world, const SceneMeta& meta, int64_t frame);

/// Tolerances from a tolerance document's JSON text (valid against tolerances.schema.json; "" or a
/// missing metric: the defaults of embra::Tolerances).
Tolerances parse_tolerances(const std::string& text);
/// A tolerance document (JSON text) holding `t`.
std::string tolerances_json(const Tolerances& t);

/// The scene schema text compiled into the library.
std::string_view scene_schema();

/// Whether `text` matches `pattern`, a "pattern" of the scene schema, as the loader checks it: in
/// code, never with std::regex (whose recursion overflows the stack on long strings). Throws
/// std::invalid_argument for a pattern the loader does not implement (the loader refuses to compile
/// a schema holding one).
bool schema_pattern_matches(std::string_view pattern, std::string_view text);

}  // namespace embra::io
