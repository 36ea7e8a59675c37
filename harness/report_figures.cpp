// results/<scene>/figures.toml (docs/REPORT.md): the caption of every figure of a scene, read
// and validated as a whole before the site shows any of them.
#include <fmt/format.h>

#include <filesystem>
#include <set>

#include "harness/report.hpp"
#include "harness/toml_reader.hpp"
#include "problems/spec.hpp"

namespace geomint {

std::vector<FigureCaption> read_figure_captions(const std::string& folder) {
  namespace fs = std::filesystem;
  const fs::path path = fs::path(folder) / "figures.toml";
  if (!fs::exists(path)) return {};
  const std::string name = path.string();
  const toml::table root = parse_toml_file(
      name, "figures file",
      "[[figure]]\nfile = \"total.svg\"\ncaption = \"What the figure shows and how to read it.\"");
  TomlBlock top(root, name);
  top.known("figure");
  top.finish();
  std::vector<FigureCaption> figures;
  std::set<std::string> stems;
  int index = 0;
  for (const toml::table* table : array_of_tables(root, "figure", name)) {
    TomlBlock block(*table, fmt::format("{}: [[figure]] #{}", name, ++index));
    FigureCaption figure;
    figure.file = block.string("file", true);
    block.rename(fmt::format("{}: [[figure]] '{}'", name, figure.file));
    figure.caption = block.string("caption", true);
    figure.wide = block.boolean("wide", false);
    block.finish();
    const fs::path file(figure.file);
    const std::string ext = file.extension().string();
    if (file.has_parent_path() || (ext != ".png" && ext != ".svg")) {
      throw InputError(fmt::format(
          "{}: key 'file' must name a .png or .svg figure in the scene folder (got '{}')",
          block.where(), figure.file));
    }
    if (!fs::is_regular_file(fs::path(folder) / file)) {
      throw InputError(fmt::format("{}: key 'file': no such figure '{}' in {}", block.where(),
                                   figure.file, folder));
    }
    if (figure.caption.find_first_not_of(" \t\n") == std::string::npos) {
      throw InputError(
          fmt::format("{}: key 'caption' is empty (say what the figure shows and how to read it)",
                      block.where()));
    }
    if (!stems.insert(file.stem().string()).second) {
      throw InputError(
          fmt::format("{}: key 'file': figure '{}' is listed twice (its PNG and SVG "
                      "are one figure: list it once)",
                      block.where(), file.stem().string()));
    }
    figures.push_back(std::move(figure));
  }
  return figures;
}

}  // namespace geomint
