// Closed surface generators for scenes: an icosphere and a rounded box. Internal to embra_io.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace embra::io {

/// Vertices (xyz triples), outward-oriented triangles and named vertex sets of a generated surface.
struct SurfaceMesh {
  std::vector<double> positions;
  std::vector<int32_t> triangles;
  std::map<std::string, std::vector<int32_t>> sets;
};

/// A sphere of `radius` about the origin: an icosahedron split `subdivisions` times (each split
/// quarters every triangle), vertices pushed onto the sphere. 12 vertices at 0, 10 n^2 + 2 after n
/// splits. Sets: top (the highest vertex), bottom (the lowest), all.
SurfaceMesh icosphere(double radius, int subdivisions);

/// The surface of a box of `size` (full extents along x, y, z) about the origin with edges and
/// corners rounded to `radius` (0 = sharp; at most half the smallest extent), each face split into
/// `resolution` x `resolution` quads. Sets: corners (the 8 cube corners' images), top (the +z
/// face), bottom (the -z face), all.
SurfaceMesh rounded_box(const std::array<double, 3>& size, double radius, int resolution);

}  // namespace embra::io
