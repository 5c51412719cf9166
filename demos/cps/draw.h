#pragma once
// World -> DrawList: the only place where the engine's state meets the renderer's types.

#include "cps/render/draw_list.h"
#include "cps/world.h"
#include "scene.h"

namespace cps::cli {

/// How to draw a world: the camera and the opacity of its planes ([0, 1]).
struct DrawStyle {
  render::Camera camera;
  float plane_opacity = 1.0f;
};

/// A snapshot of `world` for the renderer: every box and sphere, every distance constraint as a
/// rod, every plane (checkered, sized around the movable bodies). Colours come from the body
/// index, so a body keeps its colour from frame to frame.
render::DrawList draw_list(const World& world, const DrawStyle& style);

/// A camera that frames the movable bodies and the fixed rod ends of `world` as they are now,
/// with the ground level y = 0 in view (aspect = width / height, > 0).
render::Camera frame_world(const World& world, float aspect);

/// The renderer camera of a scene's preset (near/far clip planes from the eye-target distance).
render::Camera camera_from_preset(const scenes::CameraPreset& preset);

}  // namespace cps::cli
