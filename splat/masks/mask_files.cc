#include "splat/masks/mask_files.h"

#include <fmt/format.h>

#include <algorithm>
#include <regex>
#include <stdexcept>

#include "splat/error.h"

namespace splat {
namespace fs = std::filesystem;

namespace {

bool all_digits(const std::string& s) {
  return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
}

// The digits without leading zeros ("0" for zero), to compare numbers of any length.
std::string canonical_number(const std::string& digits) {
  const size_t first = digits.find_first_not_of('0');
  return first == std::string::npos ? "0" : digits.substr(first);
}

bool is_png(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".png";
}

std::string escape_regex(const std::string& literal) {
  static const std::string special = R"(\^$.|?*+()[]{})";
  std::string out;
  for (char c : literal) {
    if (special.find(c) != std::string::npos) out += '\\';
    out += c;
  }
  return out;
}

// The patterns auto-detection tries, in order (mask_files.h).
const std::vector<std::string>& known_patterns() {
  static const std::vector<std::string> patterns = {"{object}/{frame}.png", "{frame}_{object}.png",
                                                    "{*}_{object}_{frame}.png",
                                                    "{object}_{frame}.png"};
  return patterns;
}

}  // namespace

std::optional<std::string> match_frame(const std::string& token,
                                       const std::vector<std::string>& stems, FrameNaming naming) {
  if (naming == FrameNaming::kIndex) {
    if (!all_digits(token) || token.size() > 9) return std::nullopt;
    const size_t index = std::stoul(token);
    if (index >= stems.size()) return std::nullopt;
    return stems[index];
  }
  if (std::binary_search(stems.begin(), stems.end(), token)) return token;
  if (!all_digits(token)) return std::nullopt;
  const std::string number = canonical_number(token);
  std::optional<std::string> found;
  for (const std::string& stem : stems) {
    if (!all_digits(stem) || canonical_number(stem) != number) continue;
    if (found) return std::nullopt;  // "7" and "07" both exist: ambiguous
    found = stem;
  }
  return found;
}

std::vector<std::string> list_mask_files(const fs::path& folder) {
  std::vector<std::string> files;
  for (auto it = fs::recursive_directory_iterator(folder); it != fs::recursive_directory_iterator();
       ++it) {
    const auto& entry = *it;
    if (entry.path().filename().string().rfind('.', 0) == 0) {  // hidden, or a staging folder
      if (entry.is_directory()) it.disable_recursion_pending();
      continue;
    }
    if (!entry.is_regular_file() || !is_png(entry.path())) continue;
    files.push_back(fs::relative(entry.path(), folder).generic_string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

MaskPattern::MaskPattern(const std::string& pattern) : text_(pattern) {
  static const std::regex placeholder(R"(\{(object|frame|\*)\})");
  int group = 0;
  size_t last = 0;
  for (std::sregex_iterator it(pattern.begin(), pattern.end(), placeholder), end; it != end; ++it) {
    regex_ += escape_regex(pattern.substr(last, it->position() - last));
    const std::string name = (*it)[1];
    if (name == "*") {
      regex_ += ".*?";
    } else if (name == "object") {
      if (object_group_) throw std::invalid_argument("--pattern: {object} appears twice");
      regex_ += "(.+)";
      object_group_ = ++group;
    } else {
      if (frame_group_) throw std::invalid_argument("--pattern: {frame} appears twice");
      regex_ += "([^/]+)";
      frame_group_ = ++group;
    }
    last = it->position() + it->length();
  }
  regex_ += escape_regex(pattern.substr(last));
  if (!object_group_ || !frame_group_)
    throw std::invalid_argument("--pattern '" + pattern + "' must hold {object} and {frame}");
}

std::optional<std::pair<std::string, std::string>> MaskPattern::match(
    const std::string& path) const {
  const std::regex re(regex_);
  std::smatch m;
  if (!std::regex_match(path, m, re)) return std::nullopt;
  return std::make_pair(m[object_group_].str(), m[frame_group_].str());
}

std::vector<ObjectMaskFile> find_object_masks(const fs::path& folder, const MaskPattern& pattern,
                                              const std::vector<std::string>& stems,
                                              FrameNaming naming,
                                              std::vector<std::string>& skipped) {
  std::vector<ObjectMaskFile> found;
  for (const std::string& file : list_mask_files(folder)) {
    const auto names = pattern.match(file);
    const auto frame = names ? match_frame(names->second, stems, naming) : std::nullopt;
    if (!frame) {
      skipped.push_back(file);
      continue;
    }
    found.push_back({names->first, *frame, folder / file});
  }
  return found;
}

DetectedMasks detect_mask_layout(const fs::path& folder, const std::vector<std::string>& stems,
                                 FrameNaming naming) {
  const std::vector<std::string> files = list_mask_files(folder);
  if (files.empty()) throw InputError(folder, "holds no PNG masks");
  const bool per_frame = std::all_of(files.begin(), files.end(), [&](const std::string& f) {
    const std::string stem = fs::path(f).stem().string();
    return f.find('/') == std::string::npos &&
           (naming == FrameNaming::kIndex ? match_frame(stem, stems, naming).has_value()
                                          : std::binary_search(stems.begin(), stems.end(), stem));
  });
  if (per_frame) return {MaskLayout::kPerFrame, ""};
  // The first known pattern under which most files name an image.
  for (const std::string& text : known_patterns()) {
    const MaskPattern pattern(text);
    size_t matched = 0;
    for (const std::string& f : files) {
      const auto names = pattern.match(f);
      if (names && match_frame(names->second, stems, naming)) ++matched;
    }
    if (2 * matched > files.size()) return {MaskLayout::kPerObject, text};
  }
  throw InputError(folder, fmt::format("cannot tell which object and frame its {} PNG files "
                                       "hold (e.g. {}): give --pattern",
                                       files.size(), files.front()));
}

}  // namespace splat
