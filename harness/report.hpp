// `geomint report` (docs/REPORT.md): a static HTML site built from the committed
// result tables — one page per results/<scene>/ with its narrative, tables, figures, gate verdicts
// (results/gates.toml, checked in-process), provenance and citation, and an index. No JavaScript.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "harness/table.hpp"

namespace geomint {

struct ReportOptions {
  std::string results_dir = "results";  // holds <scene>/scene.toml folders
  std::string gates_path;               // "" = <results_dir>/gates.toml (absent: no gates)
  // The Markdown whose `claim | measured | scene` table gives the index's claims; "" =
  // <results_dir>/../README.md (absent: the first sentence of each scene's description).
  std::string claims_path;
  std::string out_dir = "site";
  bool quick = false;        // the CI-sized tables of results/<scene>/quick/
  std::string generator;     // footer "made by"; "" = this build's version and SHA
  std::string command_line;  // the `geomint report ...` command, shown as how to rebuild
};

struct ReportSummary {
  int scenes = 0, tables = 0, gates_passed = 0, gates_failed = 0;
  int stale_scenes = 0;  // scenes whose table.md records another scene hash than scene.toml's
  std::vector<std::string> notes;  // what was left out and why (symbolic links), one line each
  int uncaptioned_figures = 0;     // figures with no entry in their scene's figures.toml
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
// CommonMark with GitHub's tables, strikethrough and autolinks (cmark-gfm, safe mode: raw HTML
// is omitted). `link` rewrites the target of every link and image; headings move one level down
// (the page's <h1> is its title).
std::string markdown_to_html(const std::string& markdown,
                             const std::function<std::string(const std::string&)>& link = {});
// Markdown as the plain text a reader sees (an image's alt text).
std::string markdown_plain_text(const std::string& markdown);
// One line of Markdown as HTML inlines (no <p> around a single paragraph).
std::string markdown_inline_html(const std::string& markdown,
                                 const std::function<std::string(const std::string&)>& link = {});

// A scene's headline from the README's table whose header has `claim`, `measured` and `scene`
// columns (in any order, among others): the claim and measured cells as HTML inlines.
struct HeadlineClaim {
  std::string claim_html, measured_html;
};
// Scene name -> its row, for every scene the row's scene cell links to (`results/<scene>/...`);
// the first row naming a scene wins. Other tables and rows without a scene link are skipped.
std::map<std::string, HeadlineClaim> headline_claims(
    const std::string& markdown, const std::function<std::string(const std::string&)>& link = {});

// One entry of results/<scene>/figures.toml (docs/REPORT.md): the figure's file, what it shows,
// and whether it is shown full width (multi-panel figures).
struct FigureCaption {
  std::string file, caption;
  bool wide = false;
};
// Reads and validates figures.toml in `folder` as a whole: InputError naming the file and key
// for a malformed file, an unknown key, a missing or absent file, an empty caption or a figure
// listed twice. No figures.toml: no captions.
std::vector<FigureCaption> read_figure_captions(const std::string& folder);
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
