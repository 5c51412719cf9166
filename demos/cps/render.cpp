#include "render.h"

#include "draw.h"

#include "cps/render/image_ops.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace cps::cli {

int frame_count(const RenderJob& job) {
  return static_cast<int>(std::floor(job.seconds * job.fps + 1e-9)) + 1;
}

std::string frame_name(int k) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.png", k);
  return name;
}

int render_frames(const scenes::Scene& scene, std::vector<Panel>& panels, const RenderJob& job,
                  render::Renderer& renderer, render::PngWriter& writer, Progress* progress) {
  const float aspect = static_cast<float>(renderer.width()) / static_cast<float>(renderer.height());
  // The camera is fixed for the whole sequence.
  DrawStyle style{frame_world(panels.front().run->world, aspect),
                  static_cast<float>(scene.plane_opacity), job.overlays};
  if (scene.camera) style.camera = camera_from_preset(*scene.camera);
  const int label_scale = std::max(1, renderer.height() / 360);

  const int frames = frame_count(job);
  std::vector<render::Image> pictures(panels.size());
  for (int k = 0; k < frames; ++k) {
    const double t = static_cast<double>(k) / job.fps;
    for (std::size_t p = 0; p < panels.size(); ++p) {
      panels[p].run->advance_to(t);
      pictures[p] = renderer.draw(draw_list(panels[p].run->world, style));
      if (!panels[p].label.empty()) {
        char time[32];
        std::snprintf(time, sizeof time, "\nt = %.2f s", panels[p].run->world.time());
        render::draw_label(pictures[p], 4 * label_scale, 4 * label_scale, panels[p].label + time,
                           label_scale);
      }
    }
    writer.write(job.folder / frame_name(k), pictures.size() == 1
                                                 ? std::move(pictures.front())
                                                 : render::side_by_side(pictures));
    if (progress != nullptr) progress->update(k + 1);
  }
  writer.finish();
  if (progress != nullptr) progress->finish();
  return frames;
}

}  // namespace cps::cli
