// Shell words without a shell: bash's quoting of one word, and bash's splitting of a command line
// (blanks, '...', "...", backslash; no expansion). The harness writes scripts with them; the exec
// method splits its cmd= with them, so a path with a blank is written as in a shell.
#pragma once

#include <string>
#include <vector>

namespace geomint {

// A word bash and sbatch may leave bare: they give none of its characters a meaning, so plain
// paths and arguments keep reading as they always did.
bool plain_word(const std::string& text);
// One bash word that is exactly `text` (single-quoted unless plain_word): a folder named
// `x$(touch PWNED)` stays a name in every command line geomint writes for a shell.
std::string shell_quoted(const std::string& text);
// The words of a command line as bash splits it (blanks, '...', "...", backslash escapes; no
// expansion): the inverse of joining shell_quoted words with spaces. Throws InputError on an
// unterminated quote.
std::vector<std::string> shell_words(const std::string& line);

}  // namespace geomint
