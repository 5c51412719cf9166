#pragma once
// Private: CPU-side unit meshes (positions and normals, counter-clockwise outward triangles).

#include <cstdint>
#include <vector>

namespace cps::render {

/// Interleaved vertex: position (unit mesh, body frame) then normal.
struct MeshVertex {
  float position[3];
  float normal[3];
};

struct MeshData {
  std::vector<MeshVertex> vertices;
  std::vector<std::uint32_t> indices;  // triangles
};

/// The cube [-1, 1]^3 with one flat normal per face: 24 vertices, 12 triangles.
MeshData make_unit_cube();

/// Unit sphere: an icosahedron subdivided `levels` times, vertices pushed onto the sphere
/// (20 * 4^levels triangles; levels = 3 gives 1280), normal = position.
MeshData make_unit_icosphere(int levels);

}  // namespace cps::render
