// Tests of the results site writer (harness/report.hpp, docs/REPORT.md): golden pages built from
// the fixture scenes of tests/report/results/, escaping, CommonMark with GitHub tables, figure
// captions, the index's claims, gate verdicts and the replace-only-our-own-site rule.
// GEOMINT_UPDATE_GOLDEN=1 rewrites the golden files.
#include "harness/report.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "harness/shard.hpp"
#include "harness/sweep.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace report_test {
namespace {

namespace fs = std::filesystem;

const fs::path kFixture = fs::path(GEOMINT_SOURCE_DIR) / "tests" / "report";

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("geomint_report_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  ReportSummary write_fixture_site() {
    ReportOptions options;
    options.results_dir = (kFixture / "results").string();
    options.out_dir = (dir_ / "site").string();
    options.generator = "geomint (fixture)";
    options.command_line = "geomint report --results tests/report/results";
    return write_report(options);
  }
  fs::path dir_;
};

// The pages, byte for byte. The README's link out of the scene points back into the source tree
// from wherever the site is, and the index names the gates file as given: the machine-dependent
// texts, shown as @RESULTS@ and @FIXTURE@.
TEST_F(ReportTest, PagesMatchTheGoldenFiles) {
  write_fixture_site();
  const std::string results_from_page =
      fs::relative(kFixture / "results", dir_ / "site" / "tiny").generic_string();
  const bool update = std::getenv("GEOMINT_UPDATE_GOLDEN") != nullptr;
  for (const auto& [page, golden] :
       {std::pair<std::string, std::string>{"index.html", "index.html"},
        {"tiny/index.html", "tiny.html"},
        {"bare/index.html", "bare.html"}}) {
    const std::string written =
        replace_all(replace_all(read_text(dir_ / "site" / page), results_from_page, "@RESULTS@"),
                    kFixture.string(), "@FIXTURE@");
    const fs::path golden_path = kFixture / "golden" / golden;
    if (update) {
      std::ofstream(golden_path, std::ios::binary) << written;
      continue;
    }
    EXPECT_EQ(written, read_text(golden_path))
        << page << " differs from " << golden_path
        << " (GEOMINT_UPDATE_GOLDEN=1 rewrites it after a deliberate change)";
  }
}

TEST_F(ReportTest, CopiesTablesAndFiguresNextToThePages) {
  const ReportSummary summary = write_fixture_site();
  EXPECT_EQ(summary.scenes, 2);
  EXPECT_EQ(summary.tables, 2);
  EXPECT_EQ(summary.gates_passed, 2);  // energy bound and "every row ok"
  EXPECT_EQ(summary.gates_failed, 1);  // implicit Euler's order, failing on purpose
  for (const char* file : {"style.css", "tiny/summary.csv", "tiny/order.csv", "tiny/energy.png"}) {
    EXPECT_TRUE(fs::exists(dir_ / "site" / file)) << file;
  }
  // phase is drawn as PNG and SVG: the page shows the SVG only; energy has only its PNG.
  const std::string page = read_text(dir_ / "site" / "tiny" / "index.html");
  EXPECT_NE(page.find("src=\"phase.svg\""), std::string::npos);
  EXPECT_EQ(page.find("src=\"phase.png\""), std::string::npos);
  EXPECT_NE(page.find("src=\"energy.png\""), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "site" / "tiny" / "phase.svg"));
  EXPECT_EQ(read_text(dir_ / "site" / "tiny" / "order.csv"),
            read_text(kFixture / "results" / "tiny" / "order.csv"));
}

TEST_F(ReportTest, TablesHaveOneHtmlRowPerCsvRow) {
  CsvTable table = parse_csv_table("a,b\n1,x\n2,\n3,\"<y>\"\n", "t.csv");
  const std::string html = csv_table_html(table, "t.csv");
  size_t body_rows = 0;
  for (size_t at = html.find("<tr>"); at != std::string::npos; at = html.find("<tr>", at + 1)) {
    ++body_rows;
  }
  EXPECT_EQ(body_rows, 1 + table.rows.size());  // the header row, then one per CSV row
  EXPECT_NE(html.find("data-rows=\"3\""), std::string::npos);
  EXPECT_NE(html.find("<td>&lt;y&gt;</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>2</td><td></td>"), std::string::npos);  // an empty cell stays a cell
}

TEST(ReportHtml, EscapesEveryMarkupCharacter) {
  EXPECT_EQ(html_escape("<a href=\"x\">'&'</a>"),
            "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
}

TEST(ReportHtml, RendersCommonMark) {
  EXPECT_EQ(markdown_to_html("# T\n\npara `a<b>` and [l](u.csv)\n\n- x\n- y\n"),
            "<h2>T</h2>\n<p>para <code>a&lt;b&gt;</code> and <a href=\"u.csv\">l</a></p>\n"
            "<ul>\n<li>x</li>\n<li>y</li>\n</ul>\n");
  EXPECT_EQ(markdown_to_html("```\n<x>\n```\n"), "<pre><code>&lt;x&gt;\n</code></pre>\n");
  EXPECT_EQ(markdown_to_html("2. b\n3. c\n"), "<ol start=\"2\">\n<li>b</li>\n<li>c</li>\n</ol>\n");
  EXPECT_EQ(markdown_to_html("see ![a<b](f.png) now\n"),
            "<p>see <img src=\"f.png\" alt=\"a&lt;b\" /> now</p>\n");
  // Emphasis, strikethrough and autolinks (the hand-written subset printed the first as text).
  EXPECT_EQ(markdown_to_html("*e* **s** ~~x~~ https://a.org\n"),
            "<p><em>e</em> <strong>s</strong> <del>x</del> <a "
            "href=\"https://a.org\">https://a.org</a></p>\n");
}

// GitHub tables: one cell per Markdown cell, escaped pipes inside a cell, inline markup in cells.
TEST(ReportHtml, RendersGfmTables) {
  const std::string html =
      markdown_to_html("| pair | formulation 1 |\n|---|:-:|\n| *a* | `x \\| y` |\n| b |\n");
  EXPECT_NE(html.find("<table>"), std::string::npos) << html;
  EXPECT_EQ(html.find("|---"), std::string::npos) << html;
  size_t cells = 0;
  for (const char* tag : {"<th>", "<th ", "<td>", "<td "}) {
    for (size_t at = html.find(tag); at != std::string::npos; at = html.find(tag, at + 1)) ++cells;
  }
  EXPECT_EQ(cells, 6u) << html;  // a short row is padded to the header's two cells
  EXPECT_NE(html.find("<td><em>a</em></td>"), std::string::npos) << html;
  EXPECT_NE(html.find("<code>x | y</code>"), std::string::npos) << html;
  // Alignment as a style attribute: HTML5 (and tidy) know no align attribute.
  EXPECT_NE(html.find("<th style=\"text-align: center\">"), std::string::npos) << html;
}

// Raw HTML and javascript: URLs never reach the page (cmark-gfm's safe mode).
TEST(ReportHtml, OmitsRawHtml) {
  const std::string html =
      markdown_to_html("<script>alert(1)</script>\n\nx <b onclick=\"y\">b</b> [l](javascript:z)\n");
  EXPECT_EQ(html.find("<script"), std::string::npos) << html;
  EXPECT_EQ(html.find("<b "), std::string::npos) << html;
  EXPECT_EQ(html.find("javascript:"), std::string::npos) << html;
  EXPECT_NE(html.find(" l</p>"), std::string::npos) << html;  // the link's text, no <a href="">
}

// Link targets are rewritten on the parsed document: links and images, in tables too, never the
// text of a code span that looks like a link.
TEST(ReportHtml, RewritesLinksOnTheDocument) {
  const auto link = [](const std::string& target) { return "R/" + target; };
  const std::string html = markdown_to_html(
      "[a](x.md) ![i](f.png) `[c](y.md)`\n\n| t |\n|---|\n| [b](z.md) |\n\n[r]\n\n[r]: w.md\n",
      link);
  for (const char* rewritten : {"href=\"R/x.md\"", "src=\"R/f.png\"", "href=\"R/z.md\"",
                                "href=\"R/w.md\"", "<code>[c](y.md)</code>"}) {
    EXPECT_NE(html.find(rewritten), std::string::npos) << rewritten << " in " << html;
  }
}

// The index's claims come from the README's `claim | measured | scene` table, whatever its column
// order, extra columns or other tables; rows that name no scene are skipped; a row naming two
// scenes gives both the same claim.
TEST(ReportHtml, ReadsHeadlineClaimsFromTheReadmeTable) {
  const std::string readme =
      "# P\n\n| document | what |\n|---|---|\n| [a](results/x/README.md) | not a claim |\n\n"
      "| Scene | extra | Measured | Claim |\n|---|---|---|---|\n"
      "| [x](results/x/README.md) | - | 1.5e-3 at `h` | *x* keeps H \\| bounded |\n"
      "| [docs](docs/A.md) | - | 2 | no scene |\n"
      "| [y](results/y/README.md), [z](./results/z/) | - | 3 | shared |\n"
      "| [x](results/x/) | - | 9 | a later row |\n";
  const auto claims = headline_claims(readme);
  ASSERT_EQ(claims.size(), 3u);
  EXPECT_EQ(claims.at("x").claim_html, "<em>x</em> keeps H | bounded");
  EXPECT_EQ(claims.at("x").measured_html, "1.5e-3 at <code>h</code>");
  EXPECT_EQ(claims.at("y").claim_html, "shared");
  EXPECT_EQ(claims.at("z").measured_html, "3");
  // No such table, or one without a claim column: no claims.
  EXPECT_TRUE(
      headline_claims("| scene | measured |\n|---|---|\n| [x](results/x/) | 1 |\n").empty());
  EXPECT_TRUE(headline_claims("no table\n").empty());
  // A shortened table (a measured column cut away) still gives the claims.
  EXPECT_EQ(headline_claims("| claim | scene |\n|---|---|\n| c 1 | [x](results/x/) |\n")
                .at("x")
                .measured_html,
            "");
}

// figures.toml is validated as a whole: each mistake is an InputError naming the file and key.
TEST_F(ReportTest, ValidatesFiguresToml) {
  fs::copy_file(kFixture / "results" / "tiny" / "energy.png", dir_ / "energy.png");
  const auto error_of = [&](const std::string& text) -> std::string {
    std::ofstream(dir_ / "figures.toml") << text;
    try {
      read_figure_captions(dir_.string());
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  };
  const std::string ok = "[[figure]]\nfile = \"energy.png\"\ncaption = \"What it shows.\"\n";
  EXPECT_EQ(error_of(ok), "");
  ASSERT_EQ(read_figure_captions(dir_.string()).size(), 1u);
  EXPECT_FALSE(read_figure_captions(dir_.string())[0].wide);
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {ok + "colour = 1\n", "unknown key 'colour'"},
           {"title = 1\n" + ok, "unknown key 'title'"},
           {"[[figure]]\nfile = \"missing.png\"\ncaption = \"x\"\n",
            "no such figure 'missing.png'"},
           {"[[figure]]\nfile = \"energy.png\"\ncaption = \" \"\n", "key 'caption' is empty"},
           {"[[figure]]\nfile = \"energy.png\"\n", "caption"},
           {"[[figure]]\ncaption = \"x\"\n", "file"},
           {"[[figure]]\nfile = \"../energy.png\"\ncaption = \"x\"\n", "key 'file' must name"},
           {ok + ok, "listed twice"},
           {"[[figure]\n", "malformed"}}) {
    const std::string message = error_of(text);
    EXPECT_NE(message.find(expected), std::string::npos) << text << " gave: " << message;
    EXPECT_NE(message.find("figures.toml"), std::string::npos) << message;
  }
}

// Figures: each links to its full-size file with its figures.toml caption, in the file's order;
// a figure without an entry is still shown, uncaptioned, and counted.
TEST_F(ReportTest, ShowsFiguresWithTheirCaptions) {
  const ReportSummary summary = write_fixture_site();
  EXPECT_EQ(summary.uncaptioned_figures, 0);
  const std::string page = read_text(dir_ / "site" / "tiny" / "index.html");
  const size_t phase = page.find(
      "<figure class=\"wide\"><a href=\"phase.svg\"><img src=\"phase.svg\" alt=\"Phase portrait");
  const size_t energy = page.find(
      "<figure><a href=\"energy.png\"><img src=\"energy.png\" alt=\"Relative energy error");
  ASSERT_NE(phase, std::string::npos) << page;
  ASSERT_NE(energy, std::string::npos) << page;
  EXPECT_LT(phase, energy);
  EXPECT_NE(page.find("<figcaption>Phase portrait of the <em>fixture</em> run: a closed "
                      "curve.</figcaption>"),
            std::string::npos);

  const fs::path results = dir_ / "results";
  fs::copy(kFixture / "results", results, fs::copy_options::recursive);
  fs::remove(results / "tiny" / "figures.toml");
  ReportOptions options;
  options.results_dir = results.string();
  options.out_dir = (dir_ / "site2").string();
  EXPECT_EQ(write_report(options).uncaptioned_figures, 2);
  std::ofstream(results / "tiny" / "figures.toml") << "[[figure]]\nfile = \"energy.png\"\n";
  EXPECT_THROW(write_report(options), InputError);
}

// The index shows each scene's claim and measured number from the README's headline table; a
// scene without a row shows its description's first sentence.
TEST_F(ReportTest, IndexShowsTheHeadlineClaims) {
  write_fixture_site();
  const std::string index = read_text(dir_ / "site" / "index.html");
  EXPECT_NE(index.find("Störmer–Verlet keeps the energy <em>bounded</em><br><span "
                       "class=\"measured\">Measured: max |H − H0| 1.5e-3 at <code>h = "
                       "0.1</code></span>"),
            std::string::npos)
      << index;
  EXPECT_NE(index.find("Shown as the narrative when there is no README:"), std::string::npos);
}

// table.md is rendered as table.html next to the page, its Markdown tables as HTML tables, and
// the README's links to table.md lead there.
TEST_F(ReportTest, RendersTableMdAsAPage) {
  const fs::path results = dir_ / "results";
  fs::copy(kFixture / "results", results, fs::copy_options::recursive);
  std::ofstream(results / "tiny" / "table.md")
      << "# tiny\n\n| method | error |\n|---|---|\n| a | 1 |\n| b | 2 |\n";
  std::ofstream(results / "tiny" / "README.md", std::ios::app) << "\nSee [the table](table.md).\n";
  ReportOptions options;
  options.results_dir = results.string();
  options.out_dir = (dir_ / "site").string();
  write_report(options);
  const std::string table = read_text(dir_ / "site" / "tiny" / "table.html");
  EXPECT_NE(table.find("<table>"), std::string::npos) << table;
  EXPECT_NE(table.find("<td>b</td>"), std::string::npos) << table;
  EXPECT_EQ(table.find("|---"), std::string::npos) << table;
  EXPECT_NE(
      read_text(dir_ / "site" / "tiny" / "index.html").find("<a href=\"table.html\">the table</a>"),
      std::string::npos);
}

// --out is replaced whole: a folder the verb did not write is refused and left as it was.
TEST_F(ReportTest, RefusesToReplaceAFolderItDidNotWrite) {
  fs::create_directories(dir_ / "site");
  std::ofstream(dir_ / "site" / "notes.txt") << "mine";
  EXPECT_THROW(write_fixture_site(), InputError);
  EXPECT_EQ(read_text(dir_ / "site" / "notes.txt"), "mine");
  fs::remove(dir_ / "site" / "notes.txt");
  write_fixture_site();
  write_fixture_site();  // its own site, replaced
  EXPECT_TRUE(fs::exists(dir_ / "site" / "tiny" / "index.html"));
  EXPECT_FALSE(fs::exists(dir_ / "site" / "notes.txt"));
}

// The "Cite this table" blocks: each holds one BibTeX @software entry whose braces balance and
// which has the fields a citation needs, authors first; no url field without a configured URL.
TEST_F(ReportTest, CiteBlocksHoldParseableBibtex) {
  write_fixture_site();
  const std::string page = read_text(dir_ / "site" / "tiny" / "index.html");
  int entries = 0;
  for (size_t at = page.find("@software{"); at != std::string::npos;
       at = page.find("@software{", at + 1)) {
    ++entries;
    const std::string entry =
        replace_all(page.substr(at, page.find("</pre>", at) - at), "&#39;", "'");
    int depth = 0;
    size_t end = 0;
    for (size_t k = 0; k < entry.size() && end == 0; ++k) {
      depth += entry[k] == '{' ? 1 : entry[k] == '}' ? -1 : 0;
      ASSERT_GE(depth, 0) << entry;
      if (depth == 0 && entry[k] == '}') end = k;
    }
    ASSERT_NE(end, 0u) << "unbalanced braces: " << entry;
    EXPECT_EQ(entry.substr(end + 1), "\n") << entry;
    for (const char* field :
         {"author  = {{The geomint maintainers}}", "title   = {geomint: ", "version = {0.1.0}",
          "note    = {commit 0123456789ab; scene tiny, table ", "year    = {2026}"}) {
      EXPECT_NE(entry.find(field), std::string::npos) << field << " missing in\n" << entry;
    }
    EXPECT_EQ(entry.find("url"), std::string::npos) << entry;
  }
  EXPECT_EQ(entries, 2);  // summary.csv and order.csv
}

// With a repository URL (GEOMINT_REPOSITORY_URL) the citation names it; a title with BibTeX's
// special characters keeps the braces balanced.
TEST(ReportCitation, NamesTheRepositoryWhenConfigured) {
  CsvTable table = parse_csv_table("# geomint: 0.2.0 (abcdef012345)\n# date: 2027-01-02\na\n1\n",
                                   "/x/summary.csv");
  const std::string text =
      table_citation(table, "tiny", "A {curly} 50% title", "https://example.org/geomint");
  EXPECT_NE(text.find("  url     = {https://example.org/geomint},\n"), std::string::npos) << text;
  EXPECT_NE(text.find("version = {0.2.0}"), std::string::npos) << text;
  EXPECT_NE(text.find("commit abcdef012345"), std::string::npos) << text;
  EXPECT_NE(text.find("A (curly) 50\\% title"), std::string::npos) << text;
  const std::string entry = text.substr(text.find('@'));
  EXPECT_EQ(std::count(entry.begin(), entry.end(), '{'),
            std::count(entry.begin(), entry.end(), '}'));
  EXPECT_EQ(table_citation(table, "tiny", "t", "").find("url"), std::string::npos);
}

// Every path in href and src is percent-encoded: a scene folder or file named with `#`, `?` or `%`
// is linked as itself, not as a fragment, a query or an escape.
TEST_F(ReportTest, EncodesPathsInLinks) {
  EXPECT_EQ(url_path("a b#c?d%e/f.csv"), "a%20b%23c%3Fd%25e/f.csv");
  EXPECT_EQ(url_path("plain-name_1.2~/x"), "plain-name_1.2~/x");
  const fs::path results = dir_ / "results";
  fs::create_directories(results / "a#b%c?d");
  fs::copy_file(kFixture / "results" / "tiny" / "scene.toml", results / "a#b%c?d" / "scene.toml");
  fs::copy_file(kFixture / "results" / "tiny" / "summary.csv", results / "a#b%c?d" / "s#1.csv");
  fs::copy_file(kFixture / "results" / "tiny" / "energy.png", results / "a#b%c?d" / "e%1.png");
  // README links leave the scene as URLs: `%20` is a space, and the rewritten path is encoded.
  std::ofstream(results / "a#b%c?d" / "README.md")
      << "[scene](scene.toml) and [other](../other%20dir/n.md)\n";
  ReportOptions options;
  options.results_dir = results.string();
  options.out_dir = (dir_ / "site").string();
  write_report(options);
  EXPECT_NE(read_text(dir_ / "site" / "index.html").find("href=\"a%23b%25c%3Fd/index.html\""),
            std::string::npos);
  const std::string page = read_text(dir_ / "site" / "a#b%c?d" / "index.html");
  EXPECT_NE(page.find("href=\"s%231.csv\""), std::string::npos);
  EXPECT_NE(page.find("src=\"e%251.png\""), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "site" / "a#b%c?d" / "s#1.csv"));
  EXPECT_NE(page.find("href=\"../../results/a%23b%25c%3Fd/scene.toml\""), std::string::npos)
      << page;
  EXPECT_NE(page.find("href=\"../../results/other%20dir/n.md\""), std::string::npos) << page;
}

// Without --gates, each scene's own results/<scene>/gates.toml is checked on its page, whether or
// not <results>/gates.toml exists or includes it; a scene without one says so (never a silent 0).
TEST_F(ReportTest, ChecksEachScenesOwnGatesFile) {
  const fs::path results = dir_ / "results";
  fs::copy(kFixture / "results", results, fs::copy_options::recursive);
  const std::string all = read_text(results / "gates.toml");
  // The fixture's gates of `tiny`, moved beside it (the "elsewhere" gate is left behind).
  std::ofstream(results / "tiny" / "gates.toml") << all.substr(
      all.find("[[gate]]"), all.find("[[gate]]\nname = \"elsewhere") - all.find("[[gate]]"));
  fs::remove(results / "gates.toml");
  ReportOptions options;
  options.results_dir = results.string();
  options.out_dir = (dir_ / "site").string();
  ReportSummary summary = write_report(options);
  EXPECT_EQ(summary.gates_passed, 2);
  EXPECT_EQ(summary.gates_failed, 1);
  EXPECT_NE(read_text(dir_ / "site" / "bare" / "index.html").find("none (no gates file)"),
            std::string::npos);
  EXPECT_NE(read_text(dir_ / "site" / "index.html").find("no gates file"), std::string::npos);
  // An include list that names the scene's file reads it once, not twice.
  std::ofstream(results / "gates.toml") << "include = ['tiny/gates.toml']\n";
  summary = write_report(options);
  EXPECT_EQ(summary.gates_passed + summary.gates_failed, 3);
}

// A symbolic link in a scene folder would publish its target (any file of the machine): links
// are left out of the site and the gates, with a note naming them.
TEST_F(ReportTest, LeavesOutSymbolicLinks) {
  const fs::path results = dir_ / "results";
  fs::copy(kFixture / "results", results, fs::copy_options::recursive);
  std::ofstream(dir_ / "secret.csv") << "label,x\nsecret,1\n";
  fs::create_symlink(dir_ / "secret.csv", results / "tiny" / "leak.csv");
  fs::create_symlink(dir_ / "secret.csv", results / "tiny" / "leak.png");
  fs::create_directory_symlink(results / "tiny", results / "linked_scene");
  ReportOptions options;
  options.results_dir = results.string();
  options.out_dir = (dir_ / "site").string();
  const ReportSummary summary = write_report(options);
  EXPECT_FALSE(fs::exists(dir_ / "site" / "tiny" / "leak.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "site" / "tiny" / "leak.png"));
  EXPECT_FALSE(fs::exists(dir_ / "site" / "linked_scene"));
  EXPECT_EQ(read_text(dir_ / "site" / "tiny" / "index.html").find("leak"), std::string::npos);
  EXPECT_EQ(summary.scenes, 2);
  EXPECT_EQ(summary.tables, 2);
  ASSERT_EQ(summary.notes.size(), 3u);
  for (const auto& note : summary.notes) {
    EXPECT_NE(note.find("a symbolic link"), std::string::npos) << note;
  }
}

// A scene whose table.md records another scene hash than its scene.toml's (the scene was edited
// after its tables were written) is flagged on its page, in the index and in the summary; the
// same tables with the current hash are not.
TEST_F(ReportTest, FlagsTablesOfAnEditedScene) {
  const fs::path results = dir_ / "results";
  fs::copy(kFixture / "results", results, fs::copy_options::recursive);
  const fs::path scene = results / "tiny" / "scene.toml";
  const auto write_table_md = [&](const std::string& hash) {
    std::ofstream(results / "tiny" / "table.md")
        << "# tiny\n\n## How to cite\n\n| field | value |\n|---|---|\n| scene hash | " << hash
        << " |\n| date | 2026-12-04 |\n";
  };
  ReportOptions options;
  options.results_dir = results.string();
  options.out_dir = (dir_ / "site").string();
  options.generator = "geomint (fixture)";

  write_table_md(scene_content_hash(scene.string(), false));
  EXPECT_EQ(recorded_scene_hash((results / "tiny" / "table.md").string()),
            scene_content_hash(scene.string(), false));
  EXPECT_EQ(write_report(options).stale_scenes, 0);
  EXPECT_EQ(read_text(dir_ / "site" / "tiny" / "index.html").find("Stale"), std::string::npos);

  std::ofstream(scene, std::ios::app) << "# a comment edited after the tables were written\n";
  EXPECT_EQ(write_report(options).stale_scenes, 1);
  const std::string page = read_text(dir_ / "site" / "tiny" / "index.html");
  EXPECT_NE(page.find("Stale tables: scene.toml changed after these tables were written"),
            std::string::npos);
  EXPECT_NE(page.find("make reproduce-figures SCENES=tiny"), std::string::npos);
  EXPECT_NE(read_text(dir_ / "site" / "index.html").find("STALE"), std::string::npos);

  write_table_md("(not recorded)");
  EXPECT_EQ(recorded_scene_hash((results / "tiny" / "table.md").string()), "");
  EXPECT_EQ(write_report(options).stale_scenes, 1);

  options.quick = true;  // quick tables are rewritten by every gate-quick: not checked
  fs::create_directories(results / "tiny" / "quick");
  fs::copy_file(results / "tiny" / "summary.csv", results / "tiny" / "quick" / "summary.csv");
  EXPECT_EQ(write_report(options).stale_scenes, 0);
}

}  // namespace
}  // namespace report_test
}  // namespace geomint
