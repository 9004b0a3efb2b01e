// Slots with generations: the storage of every object the world hands out ids for (groups, pins,
// colliders, fields). A slot is reused after its object is destroyed, with its generation one
// higher, so an id of the destroyed object (slot index plus generation) is refused, never taken for
// the new one. T has `uint32_t generation` and `bool alive`; a default T is a dead slot.
#pragma once

#include "embra/core/world.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace embra::slots {

/// Puts `value` in the first dead slot (or a new one at the end), live, with the next generation.
template <class T>
Id create(std::vector<T>& v, T value) {
  const auto dead = std::find_if(v.begin(), v.end(), [](const T& t) { return !t.alive; });
  const size_t slot = static_cast<size_t>(dead - v.begin());
  if (slot == v.size()) v.emplace_back();
  const uint32_t generation = v[slot].generation + 1;
  value.generation = generation;
  value.alive = true;
  v[slot] = std::move(value);
  return Id{static_cast<uint32_t>(slot), generation};
}

/// The live object `id` names, or nullptr (out of range, destroyed, or an older generation).
template <class T>
const T* find(const std::vector<T>& v, Id id) {
  if (id.index >= v.size()) return nullptr;
  const T& t = v[id.index];
  return t.alive && t.generation == id.generation ? &t : nullptr;
}

/// Empties the slot of `id` (which must be live), keeping its generation.
template <class T>
void destroy(std::vector<T>& v, Id id) {
  const uint32_t generation = v[id.index].generation;
  v[id.index] = T{};
  v[id.index].generation = generation;
}

/// The number of live slots.
template <class T>
size_t live_count(const std::vector<T>& v) {
  return static_cast<size_t>(std::count_if(v.begin(), v.end(), [](const T& t) { return t.alive; }));
}

}  // namespace embra::slots
