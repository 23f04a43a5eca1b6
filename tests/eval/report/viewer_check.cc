// Compares the 3D viewer's screenshots (tests/eval/report/viewer_test.sh)
// with op2gs-render's images of the same camera; prints the figure and exits
// 1 when it is below the bound.
//
//   viewer_check rgb SHOT RENDER MIN_PSNR
//     PSNR of the RGB view against op2gs-render's rgb/ image.
//   viewer_check labels SHOT RENDER_LABELS MIN_AGREEMENT
//     Of the pixels op2gs-render's label map gives an object, the share the
//     viewer shows in that object's colour (the map's colour of the nearest
//     hue: the viewer shades colours by occupancy, the map does not).
//   viewer_check isolate SHOT RENDER_LABELS LABEL MIN_COVERAGE
//     With one object isolated: (almost) no pixel of another object's colour, and the
//     viewer covers at least MIN_COVERAGE of the object's pixels in the map.

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string>

#include "splat/image.h"
#include "splat/label/palette.h"

namespace {

using Color = std::array<int, 3>;

Color color_at(const splat::ImageRGB& image, size_t p) {
  const float* c = &image.data[3 * p];
  return {int(std::lround(255 * c[0])), int(std::lround(255 * c[1])), int(std::lround(255 * c[2]))};
}

int distance2(const Color& a, const Color& b) {
  int d = 0;
  for (int k = 0; k < 3; ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
  return d;
}

// The colours of a label map (black, the background, among them).
std::set<Color> palette_of(const splat::ImageRGB& labels) {
  std::set<Color> colors{{0, 0, 0}};
  for (size_t p = 0; p < size_t(labels.width) * labels.height; ++p)
    colors.insert(color_at(labels, p));
  return colors;
}

// The palette colour whose hue the pixel has: the viewer blends each
// object's colour with what lies behind it by its occupancy (a darker shade
// where the model is faint), where the label map keeps the colour whole. Black
// when the pixel is nearly black.
Color nearest(const std::set<Color>& palette, const Color& c) {
  const double norm = std::sqrt(double(distance2(c, {0, 0, 0})));
  if (norm < 24) return {0, 0, 0};
  Color best{};
  double best_cos = -2;
  for (const Color& p : palette) {
    const double pn = std::sqrt(double(distance2(p, {0, 0, 0})));
    if (pn == 0) continue;
    const double cos = (p[0] * c[0] + p[1] * c[1] + p[2] * c[2]) / (pn * norm);
    if (cos > best_cos) best = p, best_cos = cos;
  }
  return best;
}

void same_size(const splat::ImageRGB& a, const splat::ImageRGB& b) {
  if (a.width == b.width && a.height == b.height) return;
  fmt::print("the shot is {}x{}, op2gs-render's image {}x{}\n", a.width, a.height, b.width,
             b.height);
  std::exit(1);
}

int check(bool ok, const std::string& what) {
  fmt::print("{}: {}\n", ok ? "ok" : "FAIL", what);
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    fmt::print(stderr, "usage: viewer_check rgb|labels|isolate SHOT RENDER ...\n");
    return 2;
  }
  const std::string what = argv[1];
  const splat::ImageRGB shot = splat::read_image_rgb(argv[2]);
  const splat::ImageRGB render = splat::read_image_rgb(argv[3]);
  same_size(shot, render);
  const size_t pixels = size_t(shot.width) * shot.height;
  if (what == "rgb") {
    double sum = 0;
    for (size_t k = 0; k < shot.data.size(); ++k)
      sum += (shot.data[k] - render.data[k]) * (shot.data[k] - render.data[k]);
    const double psnr = -10 * std::log10(sum / double(shot.data.size()));
    return check(psnr >= std::atof(argv[4]), fmt::format("RGB view PSNR {:.2f} dB", psnr));
  }
  const std::set<Color> palette = palette_of(render);
  if (what == "labels") {
    size_t object = 0, agree = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const Color truth = color_at(render, p);
      if (truth == Color{0, 0, 0}) continue;
      ++object;
      agree += nearest(palette, color_at(shot, p)) == truth;
    }
    const double share = object ? double(agree) / object : 0;
    return check(
        share >= std::atof(argv[4]),
        fmt::format("label view agrees on {:.1f}% of {} object pixels", 100 * share, object));
  }
  if (what == "isolate" && argc >= 6) {
    const auto c = splat::label_color(std::atoi(argv[4]));
    const Color mine{int(std::lround(255 * c[0])), int(std::lround(255 * c[1])),
                     int(std::lround(255 * c[2]))};
    size_t others = 0, in_map = 0, covered = 0;
    for (size_t p = 0; p < pixels; ++p) {
      const Color seen = nearest(palette, color_at(shot, p));
      others += seen != mine && seen != Color{0, 0, 0};
      if (color_at(render, p) != mine) continue;
      ++in_map;
      covered += seen == mine;
    }
    const double coverage = in_map ? double(covered) / in_map : 0;
    // Blended edges may come out nearer another colour of the map: at most 1%.
    return check(others <= in_map / 100 && coverage >= std::atof(argv[5]),
                 fmt::format("isolated: {} pixels of other objects; {:.1f}% of the object's {} "
                             "pixels shown",
                             others, 100 * coverage, in_map));
  }
  fmt::print(stderr, "viewer_check: unknown check '{}'\n", what);
  return 2;
}
