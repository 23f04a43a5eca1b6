#pragma once
// Small pieces of the self-contained HTML report.

#include <string>
#include <string_view>

#include "splat/image.h"

namespace eval {

std::string html_escape(std::string_view text);
std::string base64(std::string_view bytes);
// An <img> source with the image embedded as a JPEG (quality 90).
std::string jpeg_data_uri(const splat::ImageRGB& image);
// A file's bytes embedded as a data URI of the given MIME type.
std::string file_data_uri(const std::string& file, const std::string& mime);

}  // namespace eval
