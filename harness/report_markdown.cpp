// The results site's Markdown (docs/REPORT.md): CommonMark with GitHub's tables, strikethrough and
// autolinks through Debian's cmark-gfm. Links and images are rewritten on the parsed tree (never
// by text substitution), headings move one level down, and raw HTML is omitted (safe mode).
#include <cmark-gfm-core-extensions.h>
#include <cmark-gfm.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <memory>
#include <stdexcept>
#include <vector>

#include "harness/report.hpp"

namespace geomint {

namespace {

// Safe (cmark-gfm's default: raw HTML and javascript: URLs omitted; CMARK_OPT_UNSAFE never set),
// and table alignment as style attributes: HTML5 has no align attribute.
constexpr int kOptions = CMARK_OPT_DEFAULT | CMARK_OPT_SAFE | CMARK_OPT_VALIDATE_UTF8 |
                         CMARK_OPT_TABLE_PREFER_STYLE_ATTRIBUTES;

struct ParserFree {
  void operator()(cmark_parser* parser) const { cmark_parser_free(parser); }
};
struct NodeFree {
  void operator()(cmark_node* node) const { cmark_node_free(node); }
};
struct IterFree {
  void operator()(cmark_iter* iter) const { cmark_iter_free(iter); }
};

// cmark-gfm's own rule for the URLs its safe mode drops (a case-insensitive scheme prefix).
bool unsafe_url(const std::string& url) {
  std::string lower = url.substr(0, 16);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const auto starts = [&lower](const char* prefix) { return lower.rfind(prefix, 0) == 0; };
  if (starts("data:")) {
    return !(starts("data:image/png") || starts("data:image/gif") || starts("data:image/jpeg") ||
             starts("data:image/webp"));
  }
  return starts("javascript:") || starts("vbscript:") || starts("file:");
}

using Parser = std::unique_ptr<cmark_parser, ParserFree>;
using Document = std::unique_ptr<cmark_node, NodeFree>;

Parser gfm_parser() {
  cmark_gfm_core_extensions_ensure_registered();
  std::unique_ptr<cmark_parser, ParserFree> parser(cmark_parser_new(kOptions));
  for (const char* name : {"table", "strikethrough", "autolink"}) {
    cmark_syntax_extension* extension = cmark_find_syntax_extension(name);
    if (extension == nullptr || !cmark_parser_attach_syntax_extension(parser.get(), extension)) {
      throw std::runtime_error(std::string("report: cmark-gfm has no '") + name + "' extension");
    }
  }
  return parser;
}

// Rewrites the URL of every link and image under `root` by `link`, and moves its headings one
// level down (the page's <h1> is its title).
// Links to a URL that safe mode would empty (javascript:, vbscript:, file:, data: but images)
// become their text: an <a href=""> is neither useful nor valid HTML.
void rewrite(cmark_node* root, const std::function<std::string(const std::string&)>& link) {
  std::vector<cmark_node*> unsafe_links;
  {
    std::unique_ptr<cmark_iter, IterFree> iter(cmark_iter_new(root));
    for (cmark_event_type event; (event = cmark_iter_next(iter.get())) != CMARK_EVENT_DONE;) {
      if (event != CMARK_EVENT_ENTER) continue;  // each node once
      cmark_node* node = cmark_iter_get_node(iter.get());
      const cmark_node_type type = cmark_node_get_type(node);
      if (type == CMARK_NODE_LINK || type == CMARK_NODE_IMAGE) {
        const char* given = cmark_node_get_url(node);
        const std::string url = link ? link(given ? given : "") : (given ? given : "");
        cmark_node_set_url(node, url.c_str());
        if (type == CMARK_NODE_LINK && unsafe_url(url)) unsafe_links.push_back(node);
      } else if (type == CMARK_NODE_HEADING) {
        cmark_node_set_heading_level(node, std::min(cmark_node_get_heading_level(node) + 1, 6));
      }
    }
  }
  for (cmark_node* node : unsafe_links) {
    while (cmark_node* child = cmark_node_first_child(node)) cmark_node_insert_before(node, child);
    cmark_node_free(node);
  }
}

// The parsed document, with its links and images rewritten by `link` and its headings one level
// down.
Document parse(cmark_parser* parser, const std::string& markdown,
               const std::function<std::string(const std::string&)>& link) {
  cmark_parser_feed(parser, markdown.data(), markdown.size());
  Document document(cmark_parser_finish(parser));
  rewrite(document.get(), link);
  return document;
}

// cmark's HTML of `node` (a whole document or one block).
std::string html_of(cmark_node* node, cmark_parser* parser) {
  char* html = cmark_render_html(node, kOptions, cmark_parser_get_syntax_extensions(parser));
  std::string text = html ? html : "";
  cmark_get_default_mem_allocator()->free(html);
  return text;
}

// "<p>inlines</p>\n" -> "inlines".
std::string without_paragraph(const std::string& html) {
  const std::string open = "<p>", close = "</p>\n";
  if (html.size() >= open.size() + close.size() && html.rfind(open, 0) == 0 &&
      html.compare(html.size() - close.size(), close.size(), close) == 0) {
    return html.substr(open.size(), html.size() - open.size() - close.size());
  }
  return html;
}

std::string render(const std::string& markdown,
                   const std::function<std::string(const std::string&)>& link, bool inline_only) {
  Parser parser = gfm_parser();
  Document document = parse(parser.get(), markdown, link);
  cmark_node* root = document.get();
  cmark_node* first = cmark_node_first_child(root);
  // One paragraph's inlines (a table cell's text) are rendered without the <p> around them.
  const bool unwrap = inline_only && first != nullptr &&
                      cmark_node_get_type(first) == CMARK_NODE_PARAGRAPH &&
                      cmark_node_next(first) == nullptr;
  const std::string html = html_of(root, parser.get());
  return unwrap ? without_paragraph(html) : html;
}

// The plain text of a node: its text and code literals, lower-cased and trimmed (a header cell).
std::string plain_text(cmark_node* node) {
  std::string text;
  std::unique_ptr<cmark_iter, IterFree> iter(cmark_iter_new(node));
  for (cmark_event_type event; (event = cmark_iter_next(iter.get())) != CMARK_EVENT_DONE;) {
    cmark_node* child = cmark_iter_get_node(iter.get());
    const cmark_node_type type = cmark_node_get_type(child);
    if (event == CMARK_EVENT_ENTER && (type == CMARK_NODE_TEXT || type == CMARK_NODE_CODE)) {
      const char* literal = cmark_node_get_literal(child);
      if (literal) text += literal;
    }
  }
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const size_t first = text.find_first_not_of(" \t");
  const size_t last = text.find_last_not_of(" \t");
  return first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
}

// The scenes a cell links to: `results/<scene>` or `results/<scene>/...` targets.
std::vector<std::string> linked_scenes(cmark_node* cell) {
  std::vector<std::string> scenes;
  std::unique_ptr<cmark_iter, IterFree> iter(cmark_iter_new(cell));
  for (cmark_event_type event; (event = cmark_iter_next(iter.get())) != CMARK_EVENT_DONE;) {
    cmark_node* node = cmark_iter_get_node(iter.get());
    if (event != CMARK_EVENT_ENTER || cmark_node_get_type(node) != CMARK_NODE_LINK) continue;
    std::string url = cmark_node_get_url(node) ? cmark_node_get_url(node) : "";
    if (url.rfind("./", 0) == 0) url = url.substr(2);
    const std::string prefix = "results/";
    if (url.rfind(prefix, 0) != 0) continue;
    const std::string scene =
        url.substr(prefix.size(), url.find('/', prefix.size()) - prefix.size());
    if (!scene.empty() && std::find(scenes.begin(), scenes.end(), scene) == scenes.end()) {
      scenes.push_back(scene);
    }
  }
  return scenes;
}

// The children of a table cell as HTML inlines (moved into a paragraph of a document of their
// own, which cmark can render).
std::string cell_html(cmark_node* cell, cmark_parser* parser) {
  Document document(cmark_node_new(CMARK_NODE_DOCUMENT));
  cmark_node* paragraph = cmark_node_new(CMARK_NODE_PARAGRAPH);
  cmark_node_append_child(document.get(), paragraph);
  while (cmark_node* child = cmark_node_first_child(cell)) {
    if (!cmark_node_append_child(paragraph, child)) break;
  }
  std::string html = without_paragraph(html_of(document.get(), parser));
  while (!html.empty() && html.back() == '\n') html.pop_back();
  return html;
}

}  // namespace

std::map<std::string, HeadlineClaim> headline_claims(
    const std::string& markdown, const std::function<std::string(const std::string&)>& link) {
  Parser parser = gfm_parser();
  // The scene links are read as written; the claim's own links are then rewritten by `link`.
  Document document = parse(parser.get(), markdown, {});
  std::map<std::string, HeadlineClaim> claims;
  for (cmark_node* block = cmark_node_first_child(document.get()); block != nullptr;
       block = cmark_node_next(block)) {
    if (std::string(cmark_node_get_type_string(block)) != "table") continue;
    cmark_node* header = cmark_node_first_child(block);
    if (header == nullptr) continue;
    int claim_column = -1, measured_column = -1, scene_column = -1, column = 0;
    for (cmark_node* cell = cmark_node_first_child(header); cell != nullptr;
         cell = cmark_node_next(cell), ++column) {
      const std::string name = plain_text(cell);
      if (name == "claim") claim_column = column;
      if (name == "measured") measured_column = column;
      if (name == "scene") scene_column = column;
    }
    if (claim_column < 0 || scene_column < 0) continue;  // another table of the README
    for (cmark_node* row = cmark_node_next(header); row != nullptr; row = cmark_node_next(row)) {
      std::vector<cmark_node*> cells;
      for (cmark_node* cell = cmark_node_first_child(row); cell != nullptr;
           cell = cmark_node_next(cell)) {
        cells.push_back(cell);
      }
      const auto at = [&cells](int index) {
        return index >= 0 && index < static_cast<int>(cells.size()) ? cells[index] : nullptr;
      };
      if (at(scene_column) == nullptr || at(claim_column) == nullptr) continue;
      const std::vector<std::string> scenes = linked_scenes(at(scene_column));
      if (scenes.empty()) continue;
      for (int column : {claim_column, measured_column}) {
        if (at(column) != nullptr) rewrite(at(column), link);
      }
      HeadlineClaim claim;
      claim.claim_html = cell_html(at(claim_column), parser.get());
      if (at(measured_column) != nullptr) {
        claim.measured_html = cell_html(at(measured_column), parser.get());
      }
      for (const auto& scene : scenes) claims.emplace(scene, claim);  // the first row wins
    }
  }
  return claims;
}

std::string markdown_to_html(const std::string& markdown,
                             const std::function<std::string(const std::string&)>& link) {
  return render(markdown, link, false);
}

std::string markdown_plain_text(const std::string& markdown) {
  Parser parser = gfm_parser();
  Document document = parse(parser.get(), markdown, {});
  char* text = cmark_render_plaintext(document.get(), kOptions, 0);
  std::string plain = text ? text : "";
  cmark_get_default_mem_allocator()->free(text);
  while (!plain.empty() && (plain.back() == '\n' || plain.back() == ' ')) plain.pop_back();
  return plain;
}

std::string markdown_inline_html(const std::string& markdown,
                                 const std::function<std::string(const std::string&)>& link) {
  return render(markdown, link, true);
}

}  // namespace geomint
