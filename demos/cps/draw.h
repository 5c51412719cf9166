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
/// resolve_style makes one for a scene.
struct DrawStyle {
  render::Camera camera;
  float plane_opacity = 1.0f;
  Overlays overlays;
  /// The scene's colours by body index (scenes::body_colours, linear RGB); a body beyond the end
  /// or without one takes the palette.
  std::span<const std::optional<Vec3>> body_colours;
  /// Set for a variant of --overlay: every body in this colour (linear RGB, each in [0, 1]) at
  /// opacity body_alpha (in (0, 1]), its rods in the colour at half brightness. Unset: each body
  /// in its palette colour, opaque.
  std::optional<glm::vec3> body_colour = std::nullopt;
  float body_alpha = 1.0f;
};

/// The view a command asks for (`cps render`, `cps figure`, `cps bench`): the camera by name,
/// a camera preset that replaces the scene's own, and the overlays.
struct View {
  /// A name from camera_names() (--camera).
  std::string camera = "preset";
  /// Replaces the scene's own camera preset (for "preset", "front", "side", "top") if set: the
  /// views of `cps figure paper`.
  std::optional<scenes::CameraPreset> preset;
  Overlays overlays;
};

/// A snapshot of `world` for the renderer: every box and sphere, every distance constraint as a
/// rod (unless style.overlays.rods is false), every plane (checkered, sized around the movable
/// bodies), the contact overlay if asked. Colours come from style.body_colours, else from the body
/// index, so a body keeps its colour from frame to frame. With an orbit, the camera eye is turned about the vertical axis
/// through the target by orbit_deg_per_s * world.time() degrees.
render::DrawList draw_list(const World& world, const DrawStyle& style);

/// The names `--camera` takes: "preset" (the scene's own view; for a scene without one, the
/// automatic framing), "auto" (frame the bodies as built), and "front", "side", "top": the
/// preset's target seen from the same distance along +z, along +x, and from above.
std::span<const std::string_view> camera_names();

/// The one place a scene's pictures get their camera and style: the camera that view.camera
/// names (see camera_names()) for `scene`, whose preset is view.preset if set, else the scene's
/// own; "auto", and "preset" for a scene without a preset, frame the movable bodies and fixed rod
/// ends of `as_built` (the scene's world before its first step) with the ground level y = 0 in
/// view; "front", "side" and "top" look at the preset's target (or the framed one) from the same
/// distance. Near and far clip planes follow the eye-target distance. `aspect`: width / height of
/// one picture (> 0). The style draws the planes at the scene's plane_opacity with
/// view.overlays. Throws UsageError listing the names for an unknown camera name.
DrawStyle resolve_style(const scenes::Scene& scene, const World& as_built, const View& view,
                        float aspect);

}  // namespace cps::cli
