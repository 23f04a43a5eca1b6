#include "splat/label/palette.h"

#include <algorithm>
#include <cmath>

#include "splat/id_maps.h"

namespace splat {

std::array<float, 3> label_color(int32_t label) {
  if (label <= 0) return {0.f, 0.f, 0.f};
  // Hue steps of the golden ratio spread consecutive labels far apart.
  const double h = std::fmod(0.1 + label * 0.6180339887498949, 1.0) * 6.0;
  const double s = label % 2 ? 0.85 : 0.6, v = label % 3 ? 0.95 : 0.75;
  const int sector = int(h);
  const double f = h - sector, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  const double rgb[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  return {float(rgb[sector][0]), float(rgb[sector][1]), float(rgb[sector][2])};
}

ImageRGB colorize_labels(std::span<const int32_t> labels, int width, int height) {
  ImageRGB image(width, height);
  for (size_t p = 0; p < labels.size() && p < size_t(width) * height; ++p) {
    const auto c = label_color(labels[p]);
    for (int k = 0; k < 3; ++k) image.data[3 * p + k] = c[k];
  }
  return image;
}

void write_label_map(const std::filesystem::path& folder, const std::string& stem,
                     std::span<const int32_t> labels, int width, int height) {
  IdMap ids(width, height);
  for (size_t p = 0; p < ids.ids.size(); ++p)
    ids.ids[p] = uint16_t(std::clamp(labels[p], 0, 65535));
  write_id_map(folder / (stem + ".png"), ids, 16);
  write_image_rgb(folder.parent_path() / (folder.filename().string() + "_color") / (stem + ".png"),
                  colorize_labels(labels, width, height));
}

}  // namespace splat
