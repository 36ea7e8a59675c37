// File-system helpers of the harness (docs/DESIGN.md §5): file-name-safe forms of specs for
// series and reference files, and the output checks every command runs before computing. A leaf
// module: it includes no other harness header.
#pragma once

#include <string>
#include <vector>

#include "problems/shell_words.hpp"

namespace geomint {

// File-name-safe form of a spec ("hp:alpha=0.5" → "hp_alpha_0.5").
std::string sanitize_for_path(const std::string& text);

// Checks, before any computing, that a file can be written at `path`: it is not a directory, the
// path fits PATH_MAX and each name to be created (the file's temporary included) the file
// system's NAME_MAX, and a probe file can be created and removed in its nearest existing
// ancestor folder (missing folders are created on writing). Leaves nothing behind. Throws
// InputError "<option> '<path>': <reason>".
void check_output_file(const std::string& path, const std::string& option);
// The same for a folder that will receive output files.
void check_output_dir(const std::string& path, const std::string& option);
// True when `a` and `b` name the same file: the same inode when both exist, else the same
// absolute path after resolving `.`, `..` and symbolic links of the existing part.
bool same_file_path(const std::string& a, const std::string& b);

// plain_word, shell_quoted and shell_words: problems/shell_words.hpp (included above).

}  // namespace geomint
