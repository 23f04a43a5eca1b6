#pragma once
// The report written once into two documents side by side: a Markdown
// summary and a self-contained HTML page. Every part of the report goes
// through this writer, so the two say the same; figures are HTML only (the
// Markdown is the summary).

#include <string>
#include <vector>

namespace eval {

// A table as rows of cells; rendered to HTML and Markdown alike.
struct Table {
  std::string caption;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

class ReportDocument {
 public:
  // Starts both documents with the title (and the page's style).
  explicit ReportDocument(const std::string& title);

  void heading(int level, const std::string& text);  // level 2 or 3
  void paragraph(const std::string& text);
  // A paragraph holding one link: before [text](href) after.
  void link(const std::string& before, const std::string& text, const std::string& href,
            const std::string& after);
  void table(const Table& t);
  void html_only(const std::string& html);  // figures

  const std::string& markdown() const { return md_; }
  std::string html() const { return html_ + "</body></html>\n"; }

 private:
  std::string md_, html_;
};

}  // namespace eval
