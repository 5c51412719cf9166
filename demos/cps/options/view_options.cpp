#include "options/view_options.h"

#include "options/options.h"

#include "cps/parameters.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <regex>
#include <sstream>
#include <vector>

namespace cps::cli {

PixelSize parse_size(const std::string& text) {
  static const std::regex pattern(R"((\d{1,5})x(\d{1,5}))");
  std::smatch m;
  if (!std::regex_match(text, m, pattern)) {
    throw UsageError("--size " + text + " is not WxH (e.g. 1280x720)");
  }
  PixelSize s{std::stoi(m[1]), std::stoi(m[2])};
  if (s.width < 16 || s.width > 8192 || s.height < 16 || s.height > 8192) {
    throw UsageError("--size " + text + ": width and height must be in [16, 8192] pixels");
  }
  return s;
}

namespace {

// "{preset,auto,...,track:BODY}": --camera's values in --help.
std::string camera_choices() {
  std::string text;
  for (std::string_view n : camera_names()) text += (text.empty() ? "{" : ",") + std::string(n);
  return text + "}";
}

}  // namespace

std::string check_point(const std::string& text, Vec3* point) {
  Vec3 v;
  std::size_t start = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t comma = text.find(',', start);
    if ((i < 2) != (comma != std::string::npos)) {
      return text + ": not X,Y,Z; give three decimal numbers (m) separated by commas, e.g. 10,8,20";
    }
    const std::string part = text.substr(start, i < 2 ? comma - start : std::string::npos);
    const std::optional<double> x = parse_decimal(part);
    if (!x) {
      return text + ": '" + part + "' is not a decimal number; give X,Y,Z in m, e.g. 10,8,20";
    }
    if (!std::isfinite(*x) || std::abs(*x) > kMaxCoordinate) {
      return text + ": '" + part + "' must be finite, with |value| <= 1e6 m";
    }
    v[i] = *x;
    start = comma + 1;
  }
  if (point != nullptr) *point = v;
  return {};
}

void add_view_options(CLI::App& cmd, View& view, bool& label, bool label_default) {
  Overlays& overlays = view.overlays;
  label = label_default;
  cmd.add_flag("--contacts", overlays.contacts,
               "draw the last step's contact points (red spheres) and normals (red segments, about "
               "one body size long (m), from body a towards body b); default: off");
  cmd.add_flag("--velocities", overlays.velocities,
               "draw each body's velocity as a dark blue arrow from its centre, as long as the way "
               "it goes in 0.1 s (m); default: off");
  cmd.add_flag("--forces", overlays.forces,
               "draw each contact point's force on its body b over the last step as an orange "
               "arrow, as long as the lighter body's size when the force equals its weight; "
               "default: off");
  // Each switch once: "--label --no-label" is refused, not decided by the last.
  cmd.add_flag("--rods,!--no-rods", overlays.rods,
               "draw distance constraints as rods; default: on (--no-rods hides them)")
      ->multi_option_policy(CLI::MultiOptionPolicy::Throw);
  cmd.add_flag("--label,!--no-label", label,
               std::string("write scene, variant and time (s) on each picture; default: ") +
                   (label_default ? "on (--no-label leaves the pictures bare)" : "off (variants of --compare are always labelled)"))
      ->multi_option_policy(CLI::MultiOptionPolicy::Throw);
  cmd.add_option("--camera", view.camera,
                 "view: preset (the scene's own; when --camera is not given a scene may frame "
                 "itself instead: fit:frame for intersecting_stack, fit for a scene file without "
                 "a camera), auto "
                 "(framed on the bodies as built), fit "
                 "(framed on the bodies in the action over the whole run: a headless pre-run of "
                 "the same length, all --compare variants, seen from the preset's direction; a "
                 "body far from the others is left out), fit:panel (each variant framed on its "
                 "own), fit:frame (each variant and time framed on its own, smoothed over 0.5 s), "
                 "track:BODY (the preset's view following a body, by its name in a scene file or "
                 "its index), front, side or top (the preset's target from the same distance)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& input) { return check_camera_name(input); }, camera_choices()))
      ->each([&view](const std::string&) { view.camera_given = true; });
  const CLI::Validator point(
      [](std::string& input) { return check_point(input, nullptr); }, "X,Y,Z");
  cmd.add_option_function<std::string>(
         "--eye", [&view](const std::string& text) { check_point(text, &view.eye.emplace()); },
         "camera position X,Y,Z (m, finite, |value| <= 1e6), replacing the eye of --camera's "
         "view; must differ from the target")
      ->check(point);
  cmd.add_option_function<std::string>(
         "--target",
         [&view](const std::string& text) { check_point(text, &view.target.emplace()); },
         "point the camera looks at, X,Y,Z (m, finite, |value| <= 1e6), replacing the target of "
         "--camera's view")
      ->check(point);
  cmd.add_option_function<double>(
         "--fov", [&view](double deg) { view.fov_y_deg = deg; },
         "vertical field of view (degrees, in (1, 170); typical 45), replacing --camera's; "
         "with --camera fit the distance is chosen for it")
      ->check(CLI::Validator(
          [](std::string& input) -> std::string {
            const std::optional<double> v = parse_decimal(input);
            if (!v) return input + ": not a number; give a decimal number in (1, 170) deg";
            if (!(*v > 1.0 && *v < 170.0)) return input + ": it must be in (1, 170) deg";
            return {};
          },
          "(1, 170) deg"));
  cmd.add_option("--orbit", overlays.orbit_deg_per_s,
                 "turn the camera about the vertical axis through its target (degrees per "
                 "simulated second; 0 = fixed, typical 10)")
      ->capture_default_str()
      ->check(decimal_in(-36000.0, 36000.0, false, "deg/s"));
}

}  // namespace cps::cli
