#pragma once
// --overlay of `cps render` and `cps figure`: the variants of a comparison drawn in one view as
// translucent ghosts, each in its own colour (overlay_colour), with a legend, the way Erin
// Catto's Solver2D shows several solvers in one scene.

#include "options/compare.h"
#include "pictures/compose.h"
#include "pictures/draw.h"

#include <vector>

namespace cps::cli {

/// One view of the worlds of a comparison (the same scene, one world per variant, in the
/// variants' order; at most kMaxVariants): the planes of worlds[0], and every world's bodies
/// as ghosts in its variant's colour (overlay_colour(k), drawn at opacity kGhostAlpha) with its
/// rods in the colour at half brightness. The camera and overlays are style's; the contact
/// overlay, if on, is drawn for every world (opaque red). Throws std::invalid_argument for no
/// world or more than kMaxVariants.
render::DrawList overlay_draw_list(const std::vector<const World*>& worlds, const DrawStyle& style);

/// The legend of an overlay: per variant its colour (overlay_colour, sRGB) and its
/// Variant::legend text, for the legend strip of a figure or a frame (compose.h).
std::vector<PageLegendEntry> overlay_legend(const std::vector<Variant>& variants);

}  // namespace cps::cli
