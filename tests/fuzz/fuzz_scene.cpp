// fuzz_scene: a libFuzzer target for the scene loader, through embra.h only. The input is scene
// JSON text (any bytes). A refused scene must come back as a clean status (EMBRA_ERROR_SCHEMA or
// EMBRA_ERROR_INVALID_ARGUMENT, with a message, no world). A scene that loads is stepped a few
// frames (each accepted frame leaves every position and velocity finite; a refused one leaves the
// saved world unchanged), saved, loaded back and saved again: the two saves must be the same bytes,
// and one more step of the world and of its reloaded copy must give the same bytes too.
//
// Relative OBJ paths resolve in EMBRA_FUZZ_SCENE_DIR (tests/scenes/valid, which holds the OBJ
// files its scenes name). Work is bounded: at most kFrames frames, only for worlds whose step is
// within kMaxStepWork.
#include <cstdint>
#include <string>

#include "embra/embra.h"
#include "fuzz_support.hpp"

namespace {

constexpr int kFrames = 3;
constexpr int64_t kMaxStepWork = 2000000;  // passes x (particles + constraints) per frame

using fuzz::fail;
using fuzz::note;
using fuzz::save;

embra_status load(embra_world** out, const std::string& text) {
  return embra_world_load_json(out, text.data(), static_cast<int64_t>(text.size()), EMBRA_FUZZ_SCENE_DIR);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::trace().clear();
  const std::string text(reinterpret_cast<const char*>(data), size);
  embra_world* world = nullptr;
  const embra_status s = load(&world, text);
  note(std::string("embra_world_load_json(the input) -> ") + embra_status_name(s));
  if (s != EMBRA_OK) {
    if (world != nullptr) fail("a refused load left a world");
    if (s != EMBRA_ERROR_SCHEMA && s != EMBRA_ERROR_INVALID_ARGUMENT)
      fail(std::string("the scene was refused with ") + embra_status_name(s));
    if (embra_last_error_message()[0] == '\0') fail("the scene was refused without a message");
    return 0;
  }

  std::string saved = save(world, "after loading");
  int64_t frames = 0;
  if (embra_world_get_scene_frames(world, &frames) != EMBRA_OK) fail("embra_world_get_scene_frames refused");
  for (int64_t f = 0; f < frames && f < kFrames && fuzz::small_step(world, kMaxStepWork); ++f) {
    const embra_status st = embra_world_step(world);
    note(std::string("embra_world_step -> ") + embra_status_name(st));
    if (st == EMBRA_OK) {
      fuzz::check_state(world, "after a step");
      saved = save(world, "after a step");
    } else if (st != EMBRA_ERROR_NUMERICAL) {
      fail(std::string("a step was refused with ") + embra_status_name(st));
    } else if (const std::string now = save(world, "after a refused step"); now != saved) {
      fail("a refused step changed the saved world: " + fuzz::difference(saved, now));
    }
  }

  embra_world* copy = nullptr;
  const embra_status c = load(&copy, saved);
  note(std::string("embra_world_load_json(the saved world) -> ") + embra_status_name(c));
  if (c != EMBRA_OK) fail("the saved world does not load back");
  const std::string again = save(copy, "after loading the saved world");
  if (again != saved) fail("the saved world, loaded and saved again, differs: " + fuzz::difference(saved, again));
  if (fuzz::small_step(world, kMaxStepWork)) {
    const embra_status a = embra_world_step(world);
    const embra_status b = embra_world_step(copy);
    note(std::string("embra_world_step, both -> ") + embra_status_name(a) + ", " + embra_status_name(b));
    if (a != b) fail("the world and its saved copy step with different statuses");
    const std::string after = save(world, "after the twin steps"), twin = save(copy, "after the twin steps");
    if (after != twin) fail("the world and its saved copy step to different states: " + fuzz::difference(after, twin));
  }
  embra_world_destroy(copy);
  embra_world_destroy(world);
  return 0;
}
