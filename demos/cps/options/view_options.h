#pragma once
// The picture options `cps render` and `cps figure` share: the size of a picture, the camera,
// the overlays and the labels.

#include "options/cli_fwd.h"
#include "pictures/draw.h"

#include <string>

namespace cps::cli {

/// A picture size in pixels.
struct PixelSize {
  int width = 1280;
  int height = 720;
};

/// Parses "WxH" (e.g. "1280x720"), each side in [16, 8192] pixels. Throws UsageError naming
/// `text` if it is not WxH or a side is out of range.
PixelSize parse_size(const std::string& text);

/// Largest |coordinate| (m) --eye and --target take.
inline constexpr double kMaxCoordinate = 1.0e6;

/// Checks a point "X,Y,Z" (three decimal numbers in m, finite, |value| <= kMaxCoordinate) and
/// stores it in *point if point is not null. Returns "" if it is valid, else a message naming
/// `text` and what is allowed.
std::string check_point(const std::string& text, Vec3* point);

/// Registers --contacts, --rods/--no-rods, --camera, --orbit, --eye, --target and --fov on
/// `cmd`, storing into `view`,
/// and --label/--no-label, storing into `label` (both must outlive the parse). `label_default`
/// is --label's default and is stored into `label` now. --camera takes camera_names(); --orbit
/// a finite rate in degrees per simulated second, |rate| <= 36000; --eye and --target a point
/// (check_point); --fov degrees in (1, 170).
void add_view_options(CLI::App& cmd, View& view, bool& label, bool label_default);

}  // namespace cps::cli
