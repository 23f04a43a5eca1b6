#include "eval/report/document.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "eval/report/html.h"

namespace eval {
namespace {

constexpr const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 2em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; font-size: 14px; }
caption { text-align: left; font-weight: bold; padding: 4px 0; }
th, td { border: 1px solid #bbb; padding: 3px 8px; text-align: right; }
th:first-child, td:first-child { text-align: left; }
figure { display: inline-block; margin: 4px; }
figcaption { font-size: 12px; max-width: 320px; }
.row { white-space: nowrap; overflow-x: auto; }
.legend span { font-weight: bold; }
</style>)";

std::string to_markdown(const Table& t) {
  std::string md = t.caption.empty() ? "" : t.caption + "\n\n";
  md += "| " + fmt::format("{}", fmt::join(t.header, " | ")) + " |\n|";
  for (size_t i = 0; i < t.header.size(); ++i) md += i ? " ---: |" : " --- |";
  md += "\n";
  for (const auto& row : t.rows) md += "| " + fmt::format("{}", fmt::join(row, " | ")) + " |\n";
  return md + "\n";
}

std::string to_html(const Table& t) {
  std::string h = "<table>";
  if (!t.caption.empty()) h += "<caption>" + html_escape(t.caption) + "</caption>";
  h += "<tr>";
  for (const auto& c : t.header) h += "<th>" + html_escape(c) + "</th>";
  h += "</tr>";
  for (const auto& row : t.rows) {
    h += "<tr>";
    for (const auto& c : row) h += "<td>" + html_escape(c) + "</td>";
    h += "</tr>";
  }
  return h + "</table>\n";
}

}  // namespace

ReportDocument::ReportDocument(const std::string& title) {
  md_ = "# " + title + "\n\n";
  html_ = "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>" + html_escape(title) +
          "</title>" + kStyle + "</head><body>\n<h1>" + html_escape(title) + "</h1>\n";
}

void ReportDocument::heading(int level, const std::string& text) {
  md_ += std::string(level, '#') + " " + text + "\n\n";
  html_ += fmt::format("<h{0}>{1}</h{0}>\n", level, html_escape(text));
}

void ReportDocument::paragraph(const std::string& text) {
  md_ += text + "\n\n";
  html_ += "<p>" + html_escape(text) + "</p>\n";
}

void ReportDocument::link(const std::string& before, const std::string& text,
                          const std::string& href, const std::string& after) {
  md_ += fmt::format("{}[{}]({}){}\n\n", before, text, href, after);
  html_ += fmt::format("<p>{}<a href=\"{}\">{}</a>{}</p>\n", html_escape(before), html_escape(href),
                       html_escape(text), html_escape(after));
}

void ReportDocument::table(const Table& t) {
  md_ += to_markdown(t);
  html_ += to_html(t);
}

void ReportDocument::html_only(const std::string& html) { html_ += html; }

}  // namespace eval
