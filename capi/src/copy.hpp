// Copies between a C def and the core's struct, driven by one table per def (a tuple of Copy
// rows): a row pairs a C member with the core member it stands for. The defaults are the core struct's (a C def's
// embra_default_ function copies a default-initialised core struct into it).
#pragma once

#include "embra/embra.h"

#include "embra/core/panels.hpp"
#include "embra/core/world.hpp"

#include <cstdint>
#include <tuple>

namespace embra::capi {

/// One member of a C def and its core counterpart.
template <class C, class A, class Core, class B>
struct Copy {
  A C::*c;
  B Core::*core;
};
// A deduction guide for the aggregate (clang before 17, which builds the sanitizer runs, deduces
// no aggregate's arguments by itself).
template <class C, class A, class Core, class B>
Copy(A C::*, B Core::*) -> Copy<C, A, Core, B>;

inline void assign(double& to, double from) {
  to = from;
}
inline void assign(int32_t& to, int32_t from) {
  to = from;
}
inline void assign(Vec3& to, const double (&from)[3]) {
  to = Vec3(from[0], from[1], from[2]);
}
inline void assign(double (&to)[3], const Vec3& from) {
  for (int k = 0; k < 3; ++k) to[k] = from[k];
}
inline void assign(Tolerance& to, const embra_tolerance& from) {
  to = {from.target, from.max};
}
inline void assign(embra_tolerance& to, const Tolerance& from) {
  to = {from.target, from.max};
}

/// Every row's C member into its core member.
template <class Rows, class C, class Core>
void to_core(const Rows& rows, const C& c, Core& core) {
  std::apply([&](const auto&... row) { (assign(core.*row.core, c.*row.c), ...); }, rows);
}

/// Every row's core member into its C member.
template <class Rows, class Core, class C>
void to_c(const Rows& rows, const Core& core, C& c) {
  std::apply([&](const auto&... row) { (assign(c.*row.c, core.*row.core), ...); }, rows);
}

}  // namespace embra::capi
