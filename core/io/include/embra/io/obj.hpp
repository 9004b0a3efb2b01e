// The world as Wavefront OBJ text: what `embra run` writes and embra_world_export_obj returns.
#pragma once

#include "embra/core/world.hpp"

#include <string>
#include <string_view>

namespace embra::io {

/// The world as OBJ text in the format embra.h states at embra_world_export_obj, its first line the
/// comment `# <header>`.
std::string export_obj(const World& world, std::string_view header);

}  // namespace embra::io
