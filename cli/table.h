// zhc/cli/table.h — the aligned text / Markdown tables the verbs print.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace zhc::cli {

// rows[0] is the header; the first column is left-aligned, the others right-aligned. Markdown
// adds the separator row after the header.
void print_table(std::ostream& os, const std::vector<std::vector<std::string>>& rows, bool markdown);

}  // namespace zhc::cli
