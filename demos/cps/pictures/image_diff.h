#pragma once
// Comparing two rendered pictures channel by channel, for `cps diff` and image baselines: the
// largest and mean absolute difference, the pixels past a threshold, and a picture of where they
// lie.

#include "cps/render/renderer.h"

namespace cps::cli {

/// How two RGB8 images differ. Levels are 8-bit channel values (0..255).
struct ImageDiff {
  bool same_size = false;  ///< a and b have the same width and height (else nothing is compared)
  int max_abs = 0;         ///< the largest |a - b| of any channel of any pixel, levels
  double mean_abs = 0.0;   ///< the mean |a - b| over every channel of every pixel, levels
  long long past = 0;      ///< pixels with some channel's |a - b| above the threshold
  long long pixels = 0;    ///< width x height (of a)

  /// past as a percentage of pixels (0 for an empty image).
  double past_percent() const { return pixels > 0 ? 100.0 * static_cast<double>(past) / pixels : 0.0; }
};

/// Compares `a` and `b` (RGB8, width x height x 3 bytes each) with `threshold_levels` (a
/// channel differs when |a - b| > threshold_levels, in [0, 255]). Images of different sizes
/// give same_size = false and zeros. Throws std::invalid_argument if an image's pixel count is
/// not width x height x 3.
ImageDiff compare_images(const render::Image& a, const render::Image& b, double threshold_levels);

/// Where `a` and `b` (same size) differ: the pixels past `threshold_levels` in red (255, 0, 0),
/// every other pixel a's grey level divided by 3 (the picture for context). Throws
/// std::invalid_argument for images of different sizes or bad pixel counts.
render::Image diff_picture(const render::Image& a, const render::Image& b, double threshold_levels);

}  // namespace cps::cli
