#include "eval/report/figures.h"

#include <fmt/format.h>

#include <filesystem>
#include <map>

#include "eval/metrics/lerf_mask.h"
#include "eval/metrics/ovs.h"
#include "eval/metrics/predictions.h"
#include "eval/report/html.h"
#include "splat/image.h"

namespace eval {
namespace fs = std::filesystem;

namespace {

splat::ImageRGB thumbnail(const splat::ImageRGB& image, int width) {
  if (image.width <= width) return image;
  const int height = std::max(1, int(std::lround(double(image.height) * width / image.width)));
  return splat::resize_area(image, width, height);
}

splat::ImageRGB overlay(const splat::ImageRGB& photo, const Mask& truth, const Mask* pred) {
  splat::ImageRGB out = photo;
  for (size_t p = 0; p < truth.on.size(); ++p) {
    float color[3] = {-1, -1, -1};
    const bool t = truth.on[p], e = pred && pred->on[p];
    if (!pred && t) color[0] = 1, color[1] = 0.85f, color[2] = 0;            // ground truth: yellow
    if (pred && t && e) color[0] = 0.1f, color[1] = 0.85f, color[2] = 0.1f;  // right
    if (pred && !t && e) color[0] = 0.95f, color[1] = 0.1f, color[2] = 0.1f;  // false positive
    if (pred && t && !e) color[0] = 0.1f, color[1] = 0.3f, color[2] = 1.0f;   // missed
    for (int c = 0; c < 3; ++c) {
      float& v = out.data[3 * p + c];
      v = color[0] < 0 ? 0.45f * v : 0.4f * v + 0.6f * color[c];
    }
  }
  return out;
}

std::string figure(const std::string& uri, const std::string& caption) {
  return fmt::format("<figure><img src=\"{}\"><figcaption>{}</figcaption></figure>", uri,
                     html_escape(caption));
}

// The (view, query) -> IoU of one row, from metrics.json.
std::map<std::pair<std::string, std::string>, std::pair<int, double>> row_views(const Row& r) {
  std::map<std::pair<std::string, std::string>, std::pair<int, double>> out;
  const bool lerf = r.scores.contains("queries");
  for (const json& q : lerf ? r.scores["queries"] : r.scores["classes"])
    for (const json& v : q["views"])
      out[{v["view"].get<std::string>(), q.at(lerf ? "query" : "class").get<std::string>()}] = {
          q["object"].get<int>(), percent(v["iou"])};
  return out;
}

}  // namespace

std::string scene_figures(const SceneData& s, int width) {
  const bool on_ovs = s.protocol.find("3dovs") != std::string::npos;
  const LerfMaskGroundTruth gt = on_ovs ? lerf_mask_from_ovs(read_ovs_ground_truth(s.input.scene))
                                        : read_lerf_mask_ground_truth(s.input.scene);
  std::vector<std::map<std::pair<std::string, std::string>, std::pair<int, double>>> views;
  for (const Row& r : s.rows) views.push_back(row_views(r));
  std::string h =
      "<p class=\"legend\">Masks coloured by error: <span style=\"color:#1d1\">right</span>, "
      "<span style=\"color:#e22\">predicted, not true</span>, "
      "<span style=\"color:#25f\">true, missed</span>.</p>\n";
  for (size_t k = 0; k < gt.test_views.size(); ++k) {
    const std::string& view = gt.test_views[k];
    const fs::path photo_file = s.input.scene / "images" / view;
    if (!fs::exists(photo_file) || gt.masks[k].empty()) continue;
    const splat::ImageRGB photo_full = splat::read_image_rgb(photo_file);
    h += fmt::format("<h4>{}</h4>\n", html_escape(view));
    const fs::path labels =
        s.input.render / "instance_labels_color" / (fs::path(view).stem().string() + ".png");
    if (!s.input.render.empty() && fs::exists(labels))
      h += "<div class=\"row\">" +
           figure(jpeg_data_uri(thumbnail(splat::read_image_rgb(labels), width)),
                  "instance label map") +
           "</div>\n";
    std::vector<ObjectMasks> predicted;
    for (const Row& r : s.rows)
      predicted.push_back(read_view_predictions(r.scores.at("folder").get<std::string>(), view));
    for (const auto& [query, file] : gt.masks[k]) {
      const Mask truth = read_mask(file);
      splat::ImageRGB photo = photo_full;
      if (photo.width != truth.width || photo.height != truth.height)
        photo = splat::resize_area(photo, truth.width, truth.height);
      h += "<div class=\"row\">" + figure(jpeg_data_uri(thumbnail(photo, width)), query) +
           figure(jpeg_data_uri(thumbnail(overlay(photo, truth, nullptr), width)), "ground truth");
      for (size_t i = 0; i < s.rows.size(); ++i) {
        const auto it = views[i].find({view, query});
        if (it == views[i].end()) continue;
        const auto [object, iou] = it->second;
        const auto m = predicted[i].find(object);
        const Mask pred = m == predicted[i].end()
                              ? Mask(truth.width, truth.height)
                              : resize_mask_nearest(m->second, truth.width, truth.height);
        h += figure(jpeg_data_uri(thumbnail(overlay(photo, truth, &pred), width)),
                    fmt::format("{}: object {}, IoU {}", s.rows[i].key(), object, cell(iou)));
      }
      h += "</div>\n";
    }
  }
  return h;
}

std::string curves_html(const SceneData& s, int width) {
  std::string h;
  for (const fs::path& png : s.input.curves)
    if (fs::exists(png))
      h += figure(jpeg_data_uri(thumbnail(splat::read_image_rgb(png), 3 * width)),
                  png.parent_path().filename().string() + "/" + png.filename().string());
  return h.empty() ? "" : "<h3>Training curves</h3><div class=\"row\">" + h + "</div>\n";
}

}  // namespace eval
