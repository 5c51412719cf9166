// Contact feature ids (collision.h, ContactFeatureKind): a contact point names the features it
// comes from, and keeps that name while the bodies stay in contact the same way.
#include "scene.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <set>
#include <vector>

using namespace cps;

namespace {

// The features of the manifold of bodies (a, b) in the world's last step, sorted; empty if the
// pair has no manifold.
std::vector<std::uint32_t> features(const World& world, int a, int b) {
  std::vector<std::uint32_t> f;
  for (const Manifold& m : world.manifolds()) {
    if (m.body_a != a || m.body_b != b) continue;
    for (int i = 0; i < m.count; ++i) f.push_back(m.contacts[static_cast<std::size_t>(i)].feature);
  }
  std::sort(f.begin(), f.end());
  return f;
}

// The two lines (bits 6..8 and 9..11) of a face-contact feature: 0..3 incident-face edges, 4..7
// side planes of the reference face.
int line_lo(std::uint32_t f) { return static_cast<int>((f >> 6) & 7u); }
int line_hi(std::uint32_t f) { return static_cast<int>((f >> 9) & 7u); }
bool is_incident_vertex(std::uint32_t f) {
  return contact_feature_kind(f) != kFeatureSphere && line_hi(f) < 4;
}

BodyDef box(const Vec3& half, double mass, const Vec3& position, bool is_static = false) {
  BodyDef d;
  d.shape = Shape::box(half);
  d.mass = mass;
  d.is_static = is_static;
  d.position = position;
  return d;
}

}  // namespace

TEST_CASE("a box resting on a box keeps its contact features", "[collision][features]") {
  // A 0.8 m cube on a 2 m x 0.5 m x 2 m slab on the ground. The contacts get a 1 mm margin: at
  // margin 0 a converged push drives each depth to 0 and round-off then decides whether a
  // resting corner counts as touching (tests/physics/test_stress.cpp, touching boxes), which is the
  // contact rule, not the feature ids tested here.
  WorldDef def;
  def.contact_margin = 0.001;
  def.warm_start = 0.8;
  World world(def);
  world.add_body({Shape::plane(Vec3::UnitY(), 0.0), true});
  world.add_body(box(Vec3(1.0, 0.25, 1.0), 4.0, Vec3(0.0, 0.25, 0.0)));
  world.add_body(box(Vec3::Constant(0.4), 1.0, Vec3(0.1, 0.9, -0.2)));
  for (int k = 0; k < 60; ++k) world.step();  // 1 s: settled
  const std::vector<std::uint32_t> ground = features(world, 0, 1);
  const std::vector<std::uint32_t> top = features(world, 1, 2);
  // The slab's four lower vertices (bit 1, the +y side, clear) on the plane.
  CHECK(ground == std::vector<std::uint32_t>{contact_feature(kFeatureBoxVertex, 0),
                                             contact_feature(kFeatureBoxVertex, 1),
                                             contact_feature(kFeatureBoxVertex, 4),
                                             contact_feature(kFeatureBoxVertex, 5)});
  // The cube's bottom face (incident face 1 x 2 + 1 = 3) clipped by the slab's top face
  // (reference face 2 on the first box): its four vertices, each two incident edges.
  REQUIRE(top.size() == 4);
  for (const std::uint32_t f : top) {
    CHECK(contact_feature_kind(f) == kFeatureFaceA);
    CHECK((f & 7u) == 2u);
    CHECK(((f >> 3) & 7u) == 3u);
    CHECK(is_incident_vertex(f));
  }
  for (int k = 0; k < 100; ++k) {
    world.step();
    INFO("step " << k);
    CHECK(features(world, 0, 1) == ground);
    CHECK(features(world, 1, 2) == top);
    CHECK(world.persisting_contacts() == 8);  // every point found its cached self
  }
}

TEST_CASE("a box sliding across an edge drops and gains contact features where it should",
          "[collision][features]") {
  // A 0.5 m cube slides at 1 m/s without friction over a static 2 m box towards its edge at
  // x = 1. While it is all on the face, its four contacts are the four vertices of its bottom
  // face. Once its leading edge is past x = 1 (and its centre is not yet, so it does not tip),
  // the two leading vertices are clipped away by the side plane x = 1: their features go, and
  // two points on the bottom face's side edges, cut by that side plane, come; the two trailing
  // vertices keep theirs.
  WorldDef def;
  def.friction = 0.0;
  def.contact_margin = 0.001;  // as above: no margin-0 flicker of resting contacts
  def.warm_start = 0.8;
  World world(def);
  world.add_body(box(Vec3(1.0, 0.5, 1.0), 1.0, Vec3::Zero(), true));
  BodyDef cube = box(Vec3::Constant(0.25), 1.0, Vec3(0.3, 0.75, 0.0));
  cube.velocity = Vec3(1.0, 0.0, 0.0);
  world.add_body(cube);
  std::vector<std::uint32_t> on_face;  // the features while all on the face
  std::vector<std::uint32_t> before;
  int crossings = 0;
  for (int k = 0; k < 40; ++k) {
    world.step();
    const double lead = world.body(1).x.x() + 0.25;  // leading edge (m)
    if (world.body(1).x.x() > 0.97) break;           // its centre nears the edge
    const std::vector<std::uint32_t> now = features(world, 0, 1);
    INFO("step " << k << ", leading edge at x = " << lead << " m");
    REQUIRE(now.size() == 4);
    const auto vertices = std::count_if(now.begin(), now.end(), is_incident_vertex);
    if (lead < 0.995) {
      CHECK(vertices == 4);
      if (!on_face.empty()) CHECK(now == on_face);
      if (k >= 1) CHECK(world.persisting_contacts() == 4);
      on_face = now;
    } else if (lead > 1.005) {
      CHECK(vertices == 2);
      std::vector<std::uint32_t> kept;
      std::set_intersection(now.begin(), now.end(), on_face.begin(), on_face.end(),
                            std::back_inserter(kept));
      CHECK(kept.size() == 2);  // the trailing vertices
      for (const std::uint32_t f : now) {
        if (is_incident_vertex(f)) continue;
        CHECK(line_lo(f) < 4);   // a side edge of the bottom face ...
        CHECK(line_hi(f) >= 4);  // ... cut by a side plane of the big box's top face
      }
      if (before != now) {
        ++crossings;
        // The step it crosses: two points persist, two are new.
        CHECK(world.persisting_contacts() == 2);
      } else {
        CHECK(world.persisting_contacts() == 4);
      }
    }
    before = now;
  }
  CHECK(!on_face.empty());
  CHECK(crossings == 1);
}

TEST_CASE("contact features are distinct within every manifold of the paper's scenes",
          "[collision][features]") {
  // A feature id names a point of its manifold: two points of one manifold never share one
  // (otherwise a warm start would give both the same cached lambda).
  for (const scenes::Scene& scene : scenes::paper_scenes()) {
    scenes::Run run = scenes::make_run(scene);
    std::size_t manifolds = 0;
    for (int k = 0; k < 180; ++k) {  // 3 s at 60 Hz
      run.world.step();
      for (const Manifold& m : run.world.manifolds()) {
        ++manifolds;
        std::set<std::uint32_t> seen;
        for (int i = 0; i < m.count; ++i) {
          const std::uint32_t f = m.contacts[static_cast<std::size_t>(i)].feature;
          INFO(scene.name << ", step " << k << ", bodies " << m.body_a << "-" << m.body_b);
          CHECK(contact_feature_kind(f) >= kFeatureSphere);
          CHECK(contact_feature_kind(f) <= kFeatureEdges);
          CHECK(seen.insert(f).second);
        }
      }
    }
    INFO(scene.name);
    if (scene.name != "pendulum_wave") CHECK(manifolds > 0);
  }
}
