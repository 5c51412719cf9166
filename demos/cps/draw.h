#pragma once
// World -> DrawList: the only place where the engine's state meets the renderer's types.

#include "cps/render/draw_list.h"
#include "cps/world.h"
#include "scene.h"

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cps::cli {

/// What is drawn on top of the bodies and how the camera moves. Set from the command line
/// (--contacts, --rods/--no-rods, --orbit) of `cps render` and `cps figure`.
struct Overlays {
  /// Contact points of the last step's manifolds (World::manifolds(), so they lag the drawn
  /// poses by one step and there are none before the first step): a small red sphere at each
  /// point and a red segment along its normal n, drawn from the point towards body b (the
  /// direction b is pushed). Sizes scale with the smaller movable body of the pair.
  bool contacts = false;
  /// Distance constraints (Sec. 5.2) drawn as dark rods from p_a to p_b. On by default: the
  /// pendulum scenes read as loose balls without them.
  bool rods = true;
  /// Rotation of the camera eye about the vertical axis through its target, in degrees per
  /// second of simulated time (0: fixed camera; typical 10). The angle at a picture is
  /// orbit_deg_per_s * world.time().
  double orbit_deg_per_s = 0.0;
};

/// How to draw a world: the camera, the opacity of its planes ([0, 1]) and the overlays.
struct DrawStyle {
  render::Camera camera;
  float plane_opacity = 1.0f;
  Overlays overlays;
};

/// A snapshot of `world` for the renderer: every box and sphere, every distance constraint as a
/// rod (unless style.overlays.rods is false), every plane (checkered, sized around the movable
/// bodies), the contact overlay if asked. Colours come from the body index, so a body keeps its
/// colour from frame to frame. With an orbit, the camera eye is turned about the vertical axis
/// through the target by orbit_deg_per_s * world.time() degrees.
render::DrawList draw_list(const World& world, const DrawStyle& style);

/// A camera that frames the movable bodies and the fixed rod ends of `world` as they are now,
/// with the ground level y = 0 in view (aspect = width / height, > 0).
render::Camera frame_world(const World& world, float aspect);

/// The renderer camera of a scene's preset (near/far clip planes from the eye-target distance).
render::Camera camera_from_preset(const scenes::CameraPreset& preset);

/// The names `--camera` takes: "preset" (the scene's own view; for a scene without one, the
/// automatic framing), "auto" (frame the bodies as built), and "front", "side", "top": the
/// preset's target seen from the same distance along +z, along +x, and from above.
std::span<const std::string_view> camera_names();

/// The camera preset called `name` for `scene` (see camera_names()); nullopt means "frame the
/// world automatically" (frame_world). `world` is the scene as built, used when the scene has
/// no preset of its own. Throws std::invalid_argument listing the names for an unknown one.
std::optional<scenes::CameraPreset> camera_preset(const scenes::Scene& scene, const World& world,
                                                  std::string_view name, float aspect);

}  // namespace cps::cli
