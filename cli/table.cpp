#include "table.h"

#include <algorithm>

namespace zhc::cli {

void print_table(std::ostream& os, const std::vector<std::vector<std::string>>& rows, bool markdown) {
    std::vector<size_t> width(rows[0].size(), 0);
    for (const auto& r : rows)
        for (size_t i = 0; i < r.size(); ++i) width[i] = std::max(width[i], r[i].size());
    for (size_t ri = 0; ri < rows.size(); ++ri) {
        std::string line = markdown ? "|" : "";
        for (size_t i = 0; i < rows[ri].size(); ++i) {
            const std::string& c = rows[ri][i];
            const std::string pad(width[i] - c.size(), ' ');
            const std::string cell = i == 0 ? c + pad : pad + c;
            line += markdown ? " " + cell + " |" : (i ? "  " : "") + cell;
        }
        os << line << "\n";
        if (markdown && ri == 0) {
            std::string sep = "|";
            for (size_t i = 0; i < width.size(); ++i) sep += (i == 0 ? " :" : " ") + std::string(width[i] - 1, '-') + (i == 0 ? " |" : ": |");
            os << sep << "\n";
        }
    }
}

}  // namespace zhc::cli
