// `geomint report` (docs/REPORT.md): a static HTML site built from the committed
// result tables — one page per results/<scene>/ with its narrative, tables, figures, gate verdicts
// (results/gates.toml, checked in-process), provenance and citation, and an index. No JavaScript.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "harness/table.hpp"

namespace geomint {

struct ReportOptions {
  std::string results_dir = "results";  // holds <scene>/scene.toml folders
  std::string gates_path;               // "" = <results_dir>/gates.toml (absent: no gates)
  std::string out_dir = "site";
  bool quick = false;        // the CI-sized tables of results/<scene>/quick/
  std::string generator;     // footer "made by"; "" = this build's version and SHA
  std::string command_line;  // the `geomint report ...` command, shown as how to rebuild
};

struct ReportSummary {
  int scenes = 0, tables = 0, gates_passed = 0, gates_failed = 0;
  int stale_scenes = 0;  // scenes whose table.md records another scene hash than scene.toml's
  std::vector<std::string> notes;  // what was left out and why (symbolic links), one line each
};

// Writes the site into options.out_dir (built in a sibling temporary folder and renamed, so a
// failure leaves no half-written site). InputError, before anything is written, for a missing
// results folder, no scene in it, a scene folder named like a site file, --quick with no quick
// table, a malformed gates file or table, or an --out that is unsafe to replace (the current
// folder or one above it, the results folder or one above the input, a folder this verb did not
// write) or where no file can be created. Symbolic links in the results are left out (notes).
ReportSummary write_report(const ReportOptions& options);

// The pieces of the HTML writer, exposed for the golden-file tests.
std::string html_escape(const std::string& text);
// A minimal Markdown subset: # headings, paragraphs, - / * / 1. lists, ``` code blocks,
// `code`, **bold** and [text](url) links; everything else is text. `link` rewrites link targets.
std::string markdown_to_html(const std::string& markdown,
                             const std::function<std::string(const std::string&)>& link = {});
// A CSV table as an HTML <table> (method and problem specs shortened as table.md does, numbers
// to 6 significant digits); data-csv and data-rows let the browser test count its rows.
std::string csv_table_html(const CsvTable& table, const std::string& file_name);
// A file path as a relative URL for href/src: every byte but letters, digits, `-._~/` written
// %XX, so a folder named `a#b`, `q?` or `50%` is linked as itself.
std::string url_path(const std::string& path);
// The "Cite this table" text of a result table: one line, then a BibTeX @software entry with the
// authors and title of cmake/citation.cmake, the table's version, commit, scene, file and variant,
// and `url` when `repository_url` is not empty.
std::string table_citation(const CsvTable& table, const std::string& scene,
                           const std::string& scene_title, const std::string& repository_url);

}  // namespace geomint
