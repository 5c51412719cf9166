#pragma once
// World -> DrawList: the only place where the engine's state meets the renderer's types.

#include "cps/render/draw_list.h"
#include "cps/world.h"
#include "scene.h"

#include <nlohmann/json.hpp>

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
  /// Each movable body's linear velocity v (m/s) as a dark blue arrow v kVelocityArrow_s long
  /// (the way it would go in that time), drawn from its centre of mass moved towards the eye out
  /// of its bounding sphere, so that the body does not hide it; none below 1 mm.
  bool velocities = false;
  /// Each contact point's force on body b over the last step (contact_forces: its contact and
  /// friction rows' lambda, N) as an orange arrow from the point, as long as the size of the
  /// pair's lighter movable body when the force equals that body's weight m |g|; none below
  /// 1 mm, and none where the step kept no rows.
  bool forces = false;
  /// Rotation of the camera eye about the vertical axis through its target, in degrees per
  /// second of simulated time (0: fixed camera; typical 10). The angle at a picture is
  /// orbit_deg_per_s * world.time().
  double orbit_deg_per_s = 0.0;
};

/// A camera that moves with its run (--camera track:BODY and fit:frame), or holds a run's own
/// framing (fit:panel): keyframes at the run's step times, each a target (m) and an eye-target
/// distance (m, > 0); between keyframes both are interpolated linearly, before the first and
/// after the last they hold. The eye lies along the style camera's eye - target direction.
struct CameraPath {
  std::vector<double> time_s;         ///< increasing, s
  std::vector<glm::vec3> target_m;    ///< one per time
  std::vector<float> distance_m;      ///< one per time, > 0
};

/// The force (N, world frame) each contact point of the last step put on body b of its
/// manifold (World::manifolds, in order; normals from a to b): the sum over the point's contact
/// row and its two friction rows of lambda j_b, from World::rows and World::lambda (the first
/// solve's lambda: with the paper's push factor the whole contact force; the split push's second
/// solve is the push, not a force). Empty when the step's first rows are not one contact row a
/// point (a world before its first step). No errors.
std::vector<Vec3> contact_forces(const World& world);

/// The time (s) a velocity arrow stands for: an arrow is v x this long (m). 0.1 s: a body at
/// 10 m/s gets a 1 m arrow.
inline constexpr double kVelocityArrow_s = 0.1;

/// How to draw a world: the camera, the opacity of its planes ([0, 1]), where the planes are
/// drawn and the overlays. resolve_style makes one for a scene, once for a whole run.
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
  /// Every plane is drawn as a square of half side plane_half_size_m (m, > 0) centred on its
  /// point nearest to plane_centre (m). Fixed for the whole run, so a plane's edge never moves
  /// from frame to frame (resolve_style: around the bodies' bounds, see plane_extent).
  glm::vec3 plane_centre{0.0f};
  float plane_half_size_m = 30.0f;
  /// By run (the order of resolve_style's as_built): the camera path of each run, for
  /// --camera fit:panel, fit:frame and track:BODY; empty: `camera` for every run and time.
  std::vector<CameraPath> paths;
};

/// The camera of run `run` (index into style.paths; one past the end takes the last path) at
/// time t (s): style.camera, moved along the run's path if there is one (near and far clip
/// planes following the distance). The orbit is not applied (draw_list does). No errors.
render::Camera camera_at(const DrawStyle& style, std::size_t run, double t);

/// Axis-aligned bounds (m) of what a scene shows: its movable boxes and spheres (oriented boxes
/// bounded by |R| h) and the end points of its distance constraints (rods and their fixed
/// points). `any` is false while nothing has been added.
struct Bounds {
  Vec3 lo = Vec3::Zero();
  Vec3 hi = Vec3::Zero();
  bool any = false;
  /// Grows the bounds to hold the box [a, b] (m, a <= b per axis).
  void add(const Vec3& a, const Vec3& b);
  /// Grows the bounds to hold `other` (nothing if other.any is false).
  void add(const Bounds& other);
};

/// The bounds of `world` as it is now (see Bounds); non-finite positions are skipped.
Bounds world_bounds(const World& world);

/// The bounds of a headless pre-run: a copy of every world in `worlds` (none is changed) is
/// stepped at its own dt until its time reaches `seconds` (s, >= 0; within half a step, as
/// scenes::Run::advance_to), and the union of world_bounds over the worlds as given and after
/// every step is returned. Every picture of those runs at any time in [0, seconds] (each is
/// drawn after a whole step) shows bodies inside these bounds. Costs as much physics as the
/// runs themselves.
Bounds run_bounds(std::span<const World* const> worlds, double seconds);

/// The square the planes are drawn on for bounds `b`: centre the middle of b (the origin if
/// b.any is false) and half side max(30, 3 |hi - lo|) m, large enough that its edge lies far
/// outside any view framed on b.
void plane_extent(const Bounds& b, glm::vec3& centre, float& half_size_m);

/// The view a command asks for (`cps render`, `cps figure`, `cps bench`): the camera by name,
/// a camera preset that replaces the scene's own, and the overlays.
struct View {
  /// A name from camera_names() (--camera).
  std::string camera = "preset";
  /// Whether --camera was given: if not, scene_view takes the scene's default_camera.
  bool camera_given = false;
  /// Replaces the scene's own camera preset (for "preset", "front", "side", "top") if set: the
  /// views of `cps figure paper`.
  std::optional<scenes::CameraPreset> preset;
  /// --eye, --target (m) and --fov (vertical field of view, degrees, in (1, 170)): replace the
  /// eye, the target and the field of view of the camera the name gives, if set. resolve_style
  /// refuses an eye equal to the target.
  std::optional<Vec3> eye;
  std::optional<Vec3> target;
  std::optional<double> fov_y_deg;
  Overlays overlays;
  /// True when every run is drawn in one picture (--overlay): the per-run framings (fit:panel,
  /// fit:frame) frame all runs together and track:BODY follows the body of the first run.
  bool one_picture = false;
};

/// The colour (linear RGB, each in [0, 1]) draw_list gives body `body` (its index in the world)
/// when style.body_colour is unset: the scene's own (style.body_colours) if it has one, else a
/// palette colour by index, so that neighbouring bodies differ. `cps export` uses it too.
glm::vec3 body_colour(std::size_t body, const DrawStyle& style);

/// A snapshot of `world` for the renderer: every box and sphere, every distance constraint as a
/// rod (unless style.overlays.rods is false), every plane (checkered, on the square of
/// style.plane_centre and style.plane_half_size_m), the contact overlay if asked. Colours come
/// from style.body_colours, else from the body index, so a body keeps its colour from frame to
/// frame. The camera is camera_at(style, run, world.time()) (`run`: the world's index among
/// the runs style was resolved for); with an orbit, its eye is turned about the vertical axis
/// through the target by orbit_deg_per_s * world.time() degrees.
render::DrawList draw_list(const World& world, const DrawStyle& style, std::size_t run = 0);

/// The camera as JSON for run.json and figure sidecars: eye_m, target_m (m), fov_y_deg.
nlohmann::json camera_json(const render::Camera& camera);

/// The names `--camera` takes: "preset" (the scene's own view; for a scene without one, the
/// automatic framing, and for a scene file without a "camera" in `cps render` and `cps figure`,
/// "fit": see scene_view), "auto" (frame the bodies as built), "fit" (frame the bodies in the
/// action over the whole run and every run: action_bounds of a headless pre-run, seen from the
/// preset's direction), "fit:panel" (the same, each run framed on its own), "fit:frame" (each
/// run framed on its own at each time, smoothed over kCameraSmoothing_s), "front", "side",
/// "top" (the preset's target seen from the same distance along +z, along +x, and from above)
/// and "track:BODY" (camera_names lists it as "track:BODY"; BODY a body's name in a scene file
/// or its index from 0): the preset's view moved so that its target follows the body's centre,
/// averaged over kCameraSmoothing_s.
std::span<const std::string_view> camera_names();

/// "" if `name` is a --camera value camera_names() allows (track:BODY with any non-empty BODY:
/// resolve_style checks the body), else the message: the allowed names and the nearest.
std::string check_camera_name(std::string_view name);

/// The window (s) over which fit:frame and track:BODY smooth the camera: a centred average,
/// so the camera moves without the jitter of a body's contacts. Typical 0.5 s.
inline constexpr double kCameraSmoothing_s = 0.5;

/// The bounds of the bodies of `world` in the action now: a movable box or sphere is kept while
/// its centre lies within R of the median of the movable bodies' centres (per axis), where
/// R = max(2.5 x the median distance of the centres from that median, floor_m); its whole extent is
/// added, and every end of a distance constraint within R of the median too. So one body thrown
/// or sliding far away leaves the framing while the rest stays. floor_m (m, >= 0): a radius that
/// always counts as in the action (resolve_style: the farthest body as built, so that every body
/// as built is kept). Non-finite positions are skipped; a world without movable bodies gives
/// world_bounds.
Bounds action_bounds(const World& world, double floor_m);

/// The view `cps render` and `cps figure` draw `scene` with: `view`, except that the default
/// --camera preset on a scene file (scenes::is_file_scene) without a "camera" and without
/// view.preset becomes "fit", so that bodies that move far (a thrown ball) stay in the picture
/// over the whole run; a built-in scene takes its Scene::default_camera (its preset as it
/// stands, or a framing such as fit:frame) unless view.camera_given. No errors.
View scene_view(const scenes::Scene& scene, View view);

/// The one place a scene's pictures get their camera and style: the camera that view.camera
/// names (see camera_names()) for `scene`, whose preset is view.preset if set, else the scene's
/// own; "auto", and "preset" for a scene without a preset, frame the movable bodies and fixed rod
/// ends of `as_built` (the scene's world before its first step) with the ground level y = 0 in
/// view; "front", "side" and "top" look at the preset's target (or the framed one) from the same
/// distance. Near and far clip planes follow the eye-target distance. `aspect`: width / height of
/// one picture (> 0). The style draws the planes at the scene's plane_opacity with
/// view.overlays. Throws UsageError listing the names for an unknown camera name.
/// Same as the overload below with the one world `as_built` and seconds = 0 ("fit" then frames
/// the bodies as built).
DrawStyle resolve_style(const scenes::Scene& scene, const World& as_built, const View& view,
                        float aspect);

/// The camera and style of a job whose runs start from `as_built` (one world per run, e.g. the
/// variants of --compare; at least one) and last `seconds` (s, >= 0). "fit" frames the
/// action_bounds of a headless pre-run of all of them over [0, seconds] (each world with the
/// floor of its own as built): the bounding sphere of those bounds (centre the target, radius
/// r = |hi - lo| / 2) is seen from the direction of the preset's eye (or of the automatic
/// framing's) at distance d = 1.1 r / sin(min(half vertical, half horizontal field of view)),
/// so it fits the picture with 10 % margin, for any orbit. "fit:panel" does so for each run on
/// its own (style.paths, one keyframe a run); "fit:frame" at each step of each run, the sphere
/// smoothed (frame_path); "track:BODY" keeps the preset's direction and distance and moves its
/// target along the body's smoothed centre. With view.one_picture, fit:panel is fit, fit:frame
/// frames every run together and track follows the first run's body. Then view.fov_y_deg,
/// view.eye and view.target replace the camera's (the field of view before any distance is
/// computed; on a moving camera eye and target set only its direction). The planes are drawn on
/// the square plane_extent gives for the pre-run's world_bounds with fit and track, else for
/// the bounds as built (of all runs), widened to at least 40 eye-target distances of every
/// camera (plus its target's offset from the centre) so that the ground reaches the horizon,
/// short of the far clip plane at 50 distances. Throws UsageError for a camera name
/// check_camera_name refuses, a track:BODY naming no body, or an eye equal to the target.
DrawStyle resolve_style(const scenes::Scene& scene, std::span<const World* const> as_built,
                        const View& view, float aspect, double seconds);

}  // namespace cps::cli
