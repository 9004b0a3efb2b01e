// The bounds every door enforces, written once: the C ABI (embra.h states them as EMBRA_MAX_*
// macros, pinned to these by static_assert in capi/), the scene schema (its "finite", "positive"
// and size limits, compared with these by the test scenes.limits_match_schema) and the scene
// loader, which checks the sizes a schema cannot express (products, file sizes) before it builds.
#pragma once

#include <cstdint>

namespace embra::limits {

/// Largest magnitude of any number a world holds or accepts (coordinates, forces, compliances):
/// |v| <= 1e300, so that every value a door accepts the scene format saves and loads back.
inline constexpr double kMaxAbsValue = 1e300;
/// Smallest positive value accepted where a value must be positive (masses, densities, lengths,
/// dt): its inverse (an inverse mass) stays finite.
inline constexpr double kMinPositive = 1e-300;

/// How far a rotation quaternion's length may be from 1 (collider poses, collider_pose keys).
inline constexpr double kUnitQuaternionTolerance = 1e-6;

/// Largest tolerances unit_scale (mm per metre of panel per model unit).
inline constexpr double kMaxUnitScale = 1e12;
/// Seconds per frame, at most.
inline constexpr double kMaxDt = 1e6;

/// Particles in one world (2^21: a 1448 x 1448 cloth; 3.6 GB of memory was reached at 2^24).
inline constexpr int64_t kMaxParticles = int64_t{1} << 21;
/// Constraints in one world, all kinds together.
inline constexpr int64_t kMaxConstraints = int64_t{1} << 24;
/// Work per step: substeps x iterations (each iteration a pass over every group).
inline constexpr int64_t kMaxPassesPerStep = 100000;
/// Solver threads per world (Settings::threads; 0 = every core).
inline constexpr int32_t kMaxThreads = 256;
/// A scene file embra_world_load_file reads (2 GiB): larger files are refused before they are read.
inline constexpr int64_t kMaxSceneBytes = int64_t{1} << 31;
/// An OBJ file a scene names: larger files are refused before they are read.
inline constexpr int64_t kMaxObjBytes = int64_t{256} << 20;

}  // namespace embra::limits
