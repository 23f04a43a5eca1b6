#pragma once
// The report's 3D viewer of one scene's segmented model: a folder of static
// files that any current browser opens, offline, through a local web server
// (browsers refuse module scripts and data from file://):
//   python3 -m http.server -d <report folder> 8000   then open
//   http://localhost:8000/viewer/<scene>/
//
//   viewer/vendor.min.js        three.js and Spark (@sparkjsdev/spark), the
//                               Gaussian splatting renderer, bundled from
//                               eval/report/viewer/package-lock.json
//   viewer/<scene>/index.html   the page; viewer.js its code
//   viewer/<scene>/model.spz    the stage-two model, compressed (splat/spz.h)
//   viewer/<scene>/gaussians.bin  per Gaussian: label (uint16), then sigma*
//                               (uint8, 255 = 1), in the model's order
//   viewer/<scene>/model.ply    the model at full precision (a hard link to
//                               the stage-two PLY where possible), from which
//                               the page cuts object and scene-without PLYs
//   viewer/<scene>/scene.json   cameras, objects (label, name, colour,
//                               Gaussians, oracle queries and IoU, query
//                               answers)
//
// The page shows the RGB model (sigma), the labels rendered with sigma (the
// baseline) and with sigma* (dual opacity), orbit from any training or test
// camera, show / hide / isolate objects, pick one by clicking, and download
// an object or the scene without it (select_object's rule, object_ply.h).

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace eval {

struct ViewerInput {
  std::string name;                         // the scene's name (its folder in viewer/)
  std::filesystem::path scene;              // the scene folder the stages read (cameras)
  std::filesystem::path model;              // stage two's model: checkpoint or PLY
  std::filesystem::path model_ply = {};     // optional: the same model's PLY, linked
  std::filesystem::path metrics = {};       // optional: op2gs-eval's metrics.json
  std::filesystem::path queries = {};       // optional: op2gs-query's query.json
  std::filesystem::path vote_summary = {};  // optional: op2gs-vote's summary.json (names)
};

// Writes <out>/vendor.min.js and <out>/<name>/; returns the page's path
// relative to out's parent ("viewer/<name>/index.html" for out = viewer).
std::filesystem::path write_viewer(const std::filesystem::path& out, const ViewerInput& input);

// The PLY of the highest iteration in a training run's point_cloud/ folder
// (iteration_<N>/point_cloud.ply), or an empty path when it has none.
std::filesystem::path latest_point_cloud(const std::filesystem::path& point_clouds);

// The bundled page files, embedded in the program (viewer_assets.S).
struct ViewerAsset {
  const char* name;
  std::string_view bytes;
};
std::vector<ViewerAsset> viewer_assets();

}  // namespace eval
