#pragma once
// `cps render`: steps a scene and writes its frames as PNG files (the command itself is
// add_render in command.h; render_frames is also timed by `cps bench`).

#include "pictures/compose.h"
#include "pictures/draw.h"
#include "options/progress.h"
#include "scene.h"

#include "cps/render/image_ops.h"
#include "cps/render/renderer.h"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace cps::cli {

/// What to render: duration (simulated s, > 0), frames per second of video (> 0), simulated
/// seconds per second of video (speed, > 0; typical 1, 0.25 for slow motion), and the folder
/// that receives frame_000000.png, frame_000001.png, ... Frames are speed / fps simulated
/// seconds apart.
struct RenderJob {
  double seconds = 10.0;
  double fps = 30.0;
  double speed = 1.0;
  std::filesystem::path folder;
  /// Panels per row of a frame's grid (grid_layout); 0: all panels in one row.
  int columns = 0;
  /// The frame's size in pixels (> 0 each): --size, less what does not divide among the grid's
  /// cells. 0: the panels' pictures as drawn, side by side (no caption strips then).
  int frame_width = 0;
  int frame_height = 0;
  /// --overlay: every panel's run drawn in one picture as ghosts (overlay_draw_list), with a
  /// caption strip below it (the first panel's label, if any, and the time) and a legend strip
  /// below that (heading and one entry per panel).
  bool overlay = false;
  std::string legend_heading;
  std::vector<PageLegendEntry> legend;
  /// The title strip above the panels (with --label and several panels: the scene's name, which
  /// the panels' captions then leave out); empty: none.
  std::string title;
};

/// Number of frames of a job: floor(seconds * fps / speed) + 1 (frame 0 at t = 0), in 64-bit
/// arithmetic (a count beyond kMaxFrames is refused by the render command before any work).
long long frame_count(const RenderJob& job);

/// The simulated time (s) frame k (>= 0) is meant for: k * speed / fps. The frame shows the
/// physics step nearest to it (scenes::Run::advance_to).
double frame_time(const RenderJob& job, long long k);

/// "" if frames speed / fps apart fall on exact multiples of the physics step dt (s, > 0; to
/// 1e-9 relative), else a note saying how far apart they are in steps and that each shows
/// the nearest step (and that some repeat when they are less than a step apart).
std::string frame_spacing_note(const RenderJob& job, double dt);

/// The file name of frame k (>= 0): "frame_%06lld.png".
std::string frame_name(long long k);

/// One picture in a frame: a run of the scene and its label (none if empty), written with the
/// time in a caption strip below the picture.
struct Panel {
  scenes::Run* run = nullptr;
  std::string label;
};

/// The caption page of a frame of `job` at simulated time t (s) whose panels carry these labels:
/// a grid of job.columns (one panel with job.overlay) filling job.frame_width x
/// job.frame_height, each caption its label (if any) and time_caption(t), the overlay's legend,
/// job.title, text of max(10, cell height / 30) px (the frame's cell height, so a 1280x720 frame
/// of one panel has 24 px text, a 2x3 grid of it 12 px). A caption takes at most a quarter of
/// its cell's height (caption_for_cell): a label's lines after its first (a method's description)
/// are left out of small cells, of every cell when of one. The panel size is fit_panels's and no image is set. Throws
/// std::invalid_argument if job.frame_width or frame_height is <= 0.
FigurePage frame_page(const RenderJob& job, const std::vector<std::string>& labels, double t);

/// `label` as a caption of a cell cell_width x cell_height px (> 0) in text of `font` px with a
/// time line below it: whole if its lines (wrapped, estimating a glyph 0.55 em wide) take at
/// most a quarter of the cell's height at 1.25 em a line; else its first line only (the variant,
/// "push = split"), so that small panels keep their picture. No errors.
std::string caption_for_cell(const std::string& label, double cell_width, double cell_height,
                             double font);

/// Whether the frames of `job` carry caption strips: with job.overlay (the time and the legend)
/// or when any label is not empty, and a frame size is set.
bool frame_has_captions(const RenderJob& job, const std::vector<std::string>& labels);

/// Where each panel's scene lies in job's frames (px from the top left, in reading order) and
/// the frame's size: with captions, layout_page of frame_page at the last frame's time (whose
/// time is the widest), so the scenes are what the caption strips leave; without, the frame's
/// cells (frame size / grid), abutting. A scene may be smaller than 16x16 when the text leaves
/// no room (the render command refuses that). Throws std::invalid_argument as frame_page does.
PageLayout frame_layout(const RenderJob& job, const std::vector<std::string>& labels);

/// Renders frame k at simulated time frame_time(job, k) for k = 0 .. frame_count(job) - 1 into job.folder
/// (which must exist); every panel's physics steps at its world's own dt in between. The panels
/// are drawn in a grid of job.columns per row (0: one row), each at the renderer's size, all
/// drawn with `style` (resolve_style: camera, plane opacity, overlays); with job.overlay, one
/// picture holds every panel's run as a ghost. With captions (frame_has_captions) the frame is
/// frame_page's, job.frame_width x job.frame_height, and the renderer must be frame_layout's scene size;
/// without, the pictures abut as one grid (render::grid). Drawing stays on the calling thread (it owns the GL context); each finished frame
/// goes to `writer`, which encodes it on its threads while the next frame is drawn; this returns
/// after every frame is written. `progress` (may be null) is updated once per frame. Returns the
/// number of frames (at most kMaxFrames: the caller checks frame_count first). Throws std::invalid_argument if the frames have captions and the renderer is not the size they leave, std::runtime_error if a frame cannot be drawn or written (frames
/// already written stay, each complete; none is left half-written under its final name).
long long render_frames(const DrawStyle& style, std::vector<Panel>& panels, const RenderJob& job,
                  render::Renderer& renderer, render::PngWriter& writer, Progress* progress);

}  // namespace cps::cli
