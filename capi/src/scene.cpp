// JSON scenes: loading and saving.
#include "guard.hpp"

#include "embra/core/limits.hpp"
#include "embra/io/files.hpp"
#include "embra/io/obj.hpp"

#include <memory>

using namespace embra::capi;

namespace {

embra_world* load_with(std::string_view text, const embra::io::LoadOptions& options) {
  embra::io::SceneMeta meta;
  std::unique_ptr<embra::World> w = embra::io::load_scene(text, options, meta);
  return new embra_world{std::move(*w), std::move(meta)};
}

embra_world* load(std::string_view text, const std::string& base_dir) {
  embra::io::LoadOptions options;
  options.base_dir = base_dir;
  return load_with(text, options);
}

/// Writes `text` to `path` (embra::io::replace_file: whole or not at all), or refuses.
void replace_file(const char* path, const std::string& text) {
  std::string error;
  if (!embra::io::replace_file(path, text, error)) refuse(EMBRA_ERROR_INVALID_ARGUMENT, error);
}

std::string obj_text(const embra_world* world) {
  return embra::io::export_obj(world->world, std::string("embra ") + embra_version_string());
}

}  // namespace

extern "C" {

embra_status embra_world_load_json(embra_world** out_world, const char* json, int64_t length, const char* base_dir) {
  if (out_world != nullptr) *out_world = nullptr;
  return guard("embra_world_load_json", [&] {
    need(out_world, "out_world");
    need(json, "json");
    need_count(length, "length");
    *out_world = load(std::string_view(json, static_cast<size_t>(length)), base_dir ? base_dir : ".");
  });
}

embra_load_options embra_default_load_options(void) {
  embra_load_options o{};
  o.version = EMBRA_LOAD_OPTIONS_VERSION;
  return o;
}

embra_status embra_world_load_json_with_options(embra_world** out_world, const char* json, int64_t length,
                                                const embra_load_options* options) {
  if (out_world != nullptr) *out_world = nullptr;
  return guard("embra_world_load_json_with_options", [&] {
    need(out_world, "out_world");
    need(json, "json");
    need_count(length, "length");
    need(options, "options");
    need_version(options->version, EMBRA_LOAD_OPTIONS_VERSION, "embra_load_options");
    need_flag(options->allow_paths_outside_base, "options.allow_paths_outside_base");
    embra::io::LoadOptions o;
    o.base_dir = options->base_dir ? options->base_dir : ".";
    o.allow_paths_outside_base = options->allow_paths_outside_base == 1;
    *out_world = load_with(std::string_view(json, static_cast<size_t>(length)), o);
  });
}

embra_status embra_world_load_file(embra_world** out_world, const char* path) {
  if (out_world != nullptr) *out_world = nullptr;
  return guard("embra_world_load_file", [&] {
    need(out_world, "out_world");
    need(path, "path");
    std::string text, error;
    if (!embra::io::read_regular_file(path, embra::limits::kMaxSceneBytes, text, error))
      refuse(EMBRA_ERROR_INVALID_ARGUMENT, std::string(path) + " " + error);
    *out_world = load(text, embra::io::folder_of(path));
  });
}

embra_status embra_world_save_json(const embra_world* world, char* out, int64_t capacity, int64_t* out_length) {
  return guard("embra_world_save_json", world, [&] {
    need(out_length, "out_length");
    write_text(embra::io::save_scene(world->world, world->meta), out, capacity, out_length);
  });
}

embra_status embra_world_save_file(const embra_world* world, const char* path) {
  return guard("embra_world_save_file", world, [&] {
    need(path, "path");
    replace_file(path, embra::io::save_scene(world->world, world->meta));
  });
}

embra_status embra_world_export_obj(const embra_world* world, char* out, int64_t capacity, int64_t* out_length) {
  return guard("embra_world_export_obj", world, [&] {
    need(out_length, "out_length");
    write_text(obj_text(world), out, capacity, out_length);
  });
}

embra_status embra_world_write_obj(const embra_world* world, const char* path) {
  return guard("embra_world_write_obj", world, [&] {
    need(path, "path");
    replace_file(path, obj_text(world));
  });
}

embra_status embra_world_get_scene_frames(const embra_world* world, int64_t* out_frames) {
  return guard("embra_world_get_scene_frames", world, [&] {
    need(out_frames, "out_frames");
    *out_frames = world->meta.frames;
  });
}

}  // extern "C"
