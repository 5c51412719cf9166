#pragma once
// `cps render`: steps a scene and writes its frames as PNG files.

#include "scene.h"

#include "cps/render/renderer.h"

#include <filesystem>
#include <string>
#include <vector>

namespace cps::cli {

/// What to render: duration (s, > 0), frames per second of simulated time (> 0), and the folder
/// that receives frame_000000.png, frame_000001.png, ...
struct RenderJob {
  double seconds = 10.0;
  double fps = 30.0;
  std::filesystem::path folder;
};

/// One picture in a frame: a run of the scene and the label written on it (none if empty).
struct Panel {
  scenes::Run* run = nullptr;
  std::string label;
};

/// Renders frame k at simulated time k / fps for k = 0 .. floor(seconds * fps); every panel's
/// physics steps at its world's own dt in between. The panels are drawn side by side, each at
/// the renderer's size, so a frame is (panels x renderer width) by renderer height pixels.
/// The camera is the scene's preset, or frames the first panel's world as built. Returns the
/// number of frames written. Progress goes to stderr. Throws std::runtime_error if a frame
/// cannot be written.
int render_frames(const scenes::Scene& scene, std::vector<Panel>& panels, const RenderJob& job,
                  render::Renderer& renderer);

}  // namespace cps::cli
