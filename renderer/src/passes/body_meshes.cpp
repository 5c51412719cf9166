// The instanced unit meshes of the bodies (see body_meshes.h).

#include "passes/body_meshes.h"

#include "passes/pass_common.h"

#include <cstddef>
#include <cstdint>

namespace cps::render {

InstancedMesh::InstancedMesh(const MeshData& mesh)
    : vao(gl::VertexArray::create()),
      vertices(gl::Buffer::create()),
      indices(gl::Buffer::create()),
      index_count(static_cast<GLsizei>(mesh.indices.size())) {
  glBindVertexArray(vao.id());
  fill_static(GL_ARRAY_BUFFER, vertices, mesh.vertices.data(),
              mesh.vertices.size() * sizeof(MeshVertex));
  float_attribs(vertices, 0, sizeof(MeshVertex),
                {{3, offsetof(MeshVertex, position)}, {3, offsetof(MeshVertex, normal)}}, false);
  fill_static(GL_ELEMENT_ARRAY_BUFFER, indices, mesh.indices.data(),
              mesh.indices.size() * sizeof(std::uint32_t));
  float_attribs(instances.buffer(), 2, sizeof(BodyInstance),
                {{3, offsetof(BodyInstance, center)}, {4, offsetof(BodyInstance, orientation)},
                 {3, offsetof(BodyInstance, half_extents)}, {4, offsetof(BodyInstance, color)}},
                true);
  glBindVertexArray(0);
}

void InstancedMesh::draw() const {
  if (instances.count() == 0) return;
  glBindVertexArray(vao.id());
  glDrawElementsInstanced(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr, instances.count());
}

BodyMeshes::BodyMeshes()
    : cube(make_unit_cube()),
      spheres{InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions)),
              InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions + 1)),
              InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions + 2)),
              InstancedMesh(make_unit_icosphere(k_sphere_min_subdivisions + 3))} {}

void BodyMeshes::upload(const std::vector<BodyInstance>& boxes,
                        const std::array<std::vector<BodyInstance>, k_sphere_lods>& sphere_lists) {
  cube.instances.upload(boxes);
  for (std::size_t i = 0; i < spheres.size(); ++i) spheres[i].instances.upload(sphere_lists[i]);
}

void BodyMeshes::draw_spheres() const {
  for (const InstancedMesh& s : spheres) s.draw();
}

}  // namespace cps::render
