#include "view_options.h"

#include "options.h"

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

void add_view_options(CLI::App& cmd, View& view, bool& label, bool label_default) {
  Overlays& overlays = view.overlays;
  label = label_default;
  cmd.add_flag("--contacts", overlays.contacts,
               "draw the last step's contact points (red spheres) and normals (red segments, about "
               "one body size long (m), from body a towards body b); default: off");
  cmd.add_flag("--rods,!--no-rods", overlays.rods,
               "draw distance constraints as rods; default: on (--no-rods hides them)");
  cmd.add_flag("--label,!--no-label", label,
               std::string("write scene, variant and time (s) on each picture; default: ") +
                   (label_default ? "on (--no-label leaves the pictures bare)" : "off (variants of --compare are always labelled)"));
  cmd.add_option("--camera", view.camera,
                 "view: preset (the scene's own), auto (framed on the bodies as built), front, side "
                 "or top (the preset's target from the same distance)")
      ->capture_default_str()
      ->check(CLI::IsMember(std::vector<std::string>(camera_names().begin(),
                                                     camera_names().end())));
  cmd.add_option("--orbit", overlays.orbit_deg_per_s,
                 "turn the camera about the vertical axis through its target (degrees per "
                 "simulated second; 0 = fixed, typical 10)")
      ->capture_default_str()
      ->check(decimal_in(-36000.0, 36000.0, false, "deg/s"));
}

}  // namespace cps::cli
