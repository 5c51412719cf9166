#pragma once
// Private: the unit meshes bodies are drawn with (the cube and the icosphere levels of detail),
// each with its per-instance buffer, shared by the shadow pass and the body pass.

#include "frame_plan.h"
#include "gl_objects.h"
#include "meshes.h"
#include "passes/pass_common.h"

#include <array>
#include <vector>

namespace cps::render {

/// A unit mesh (meshes.h) in GL buffers with its per-instance BodyInstance buffer (the attribute
/// layout of body.vert.glsl: 0 position, 1 normal, 2-5 the instance's centre, orientation, half
/// extents, colour).
struct InstancedMesh {
  gl::VertexArray vao;
  gl::Buffer vertices;
  gl::Buffer indices;
  InstanceBuffer instances;
  GLsizei index_count = 0;

  explicit InstancedMesh(const MeshData& mesh);

  /// Draws the uploaded instances (nothing when there are none) with the program in use.
  void draw() const;
};

/// The cube (boxes) and the icospheres of subdivision k_sphere_min_subdivisions + i, i in
/// [0, k_sphere_lods) (spheres, coarse to fine). Created with the context current.
struct BodyMeshes {
  InstancedMesh cube;
  std::array<InstancedMesh, k_sphere_lods> spheres;

  BodyMeshes();

  /// Replaces the instances: `boxes` for the cube, spheres[i] for level of detail i.
  void upload(const std::vector<BodyInstance>& boxes,
              const std::array<std::vector<BodyInstance>, k_sphere_lods>& sphere_lists);
  /// Draws every sphere level's instances, coarse to fine.
  void draw_spheres() const;
};

}  // namespace cps::render
