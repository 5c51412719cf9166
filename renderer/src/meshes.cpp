#include "meshes.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

namespace cps::render {

MeshData make_unit_cube() {
  MeshData mesh;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {1, -1}) {
      glm::vec3 n(0.0f);
      n[axis] = static_cast<float>(sign);
      glm::vec3 u(0.0f);
      glm::vec3 v(0.0f);
      u[(axis + 1) % 3] = 1.0f;  // u x v = +e_axis
      v[(axis + 2) % 3] = 1.0f;
      const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
      const std::array<glm::vec2, 4> corners = {glm::vec2(-1, -1), glm::vec2(1, -1),
                                                glm::vec2(1, 1), glm::vec2(-1, 1)};
      for (const glm::vec2& c : corners) {
        const glm::vec3 p = n + c.x * u + c.y * v;
        mesh.vertices.push_back({{p.x, p.y, p.z}, {n.x, n.y, n.z}});
      }
      // Counter-clockwise seen from outside: keep the order for +axis, reverse it for -axis.
      const std::array<std::uint32_t, 6> pos = {0, 1, 2, 0, 2, 3};
      const std::array<std::uint32_t, 6> neg = {0, 2, 1, 0, 3, 2};
      for (std::uint32_t i : (sign > 0 ? pos : neg)) mesh.indices.push_back(base + i);
    }
  }
  return mesh;
}

MeshData make_unit_icosphere(int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> points = {
      {-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
      {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (glm::vec3& p : points) p = glm::normalize(p);
  std::vector<std::array<std::uint32_t, 3>> faces = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};

  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      points.push_back(glm::normalize(points[a] + points[b]));
      const auto id = static_cast<std::uint32_t>(points.size() - 1);
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    finer.reserve(faces.size() * 4);
    for (const auto& f : faces) {
      const std::uint32_t ab = mid(f[0], f[1]);
      const std::uint32_t bc = mid(f[1], f[2]);
      const std::uint32_t ca = mid(f[2], f[0]);
      finer.push_back({f[0], ab, ca});
      finer.push_back({f[1], bc, ab});
      finer.push_back({f[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    faces = std::move(finer);
  }

  MeshData mesh;
  mesh.vertices.reserve(points.size());
  for (const glm::vec3& p : points) mesh.vertices.push_back({{p.x, p.y, p.z}, {p.x, p.y, p.z}});
  mesh.indices.reserve(faces.size() * 3);
  for (const auto& f : faces) {
    const glm::vec3 a = points[f[0]];
    const glm::vec3 b = points[f[1]];
    const glm::vec3 c = points[f[2]];
    const bool outward = glm::dot(glm::cross(b - a, c - a), a + b + c) > 0.0f;
    mesh.indices.push_back(f[0]);
    mesh.indices.push_back(outward ? f[1] : f[2]);
    mesh.indices.push_back(outward ? f[2] : f[1]);
  }
  return mesh;
}

}  // namespace cps::render
