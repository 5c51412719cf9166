// compare_images and diff_picture (demos/cps/pictures/image_diff.h), in-process, on images whose
// differences are known exactly.
#include "pictures/image_diff.h"

#include <catch2/catch.hpp>

#include <stdexcept>

using cps::cli::ImageDiff;
using cps::render::Image;

namespace {

Image filled(int w, int h, std::uint8_t v) { return {w, h, std::vector<std::uint8_t>(w * h * 3, v)}; }

}  // namespace

TEST_CASE("compare_images counts the pixels past the threshold and the largest and mean difference",
          "[diff]") {
  const Image a = filled(4, 5, 100);
  Image b = a;
  CHECK(cps::cli::compare_images(a, b, 0).past == 0);
  b.pixels[0] = 110;   // pixel 0: one channel 10 levels off
  b.pixels[4] = 92;    // pixel 1: green 8 levels off (not past 8)
  b.pixels[59] = 103;  // pixel 19: blue 3 levels off
  const ImageDiff d = cps::cli::compare_images(a, b, 8);
  CHECK(d.same_size);
  CHECK(d.pixels == 20);
  CHECK(d.max_abs == 10);
  CHECK(d.past == 1);
  CHECK(d.past_percent() == Approx(5.0));
  CHECK(d.mean_abs == Approx(21.0 / 60.0));
  CHECK(cps::cli::compare_images(a, b, 2).past == 3);
  // Pixels past the threshold are red in the picture, the others a's grey / 3.
  const Image picture = cps::cli::diff_picture(a, b, 8);
  CHECK(picture.pixels[0] == 255);
  CHECK(picture.pixels[1] == 0);
  CHECK(picture.pixels[3] == 33);  // (100 + 100 + 100) / 9
  // Another size: nothing compared, and no picture.
  CHECK_FALSE(cps::cli::compare_images(a, filled(5, 4, 100), 8).same_size);
  CHECK_THROWS_AS(cps::cli::diff_picture(a, filled(5, 4, 100), 8), std::invalid_argument);
  Image broken = a;
  broken.pixels.pop_back();
  CHECK_THROWS_AS(cps::cli::compare_images(a, broken, 8), std::invalid_argument);
}
