#include "formats/io/depfile.h"

namespace zhc {

namespace {
Error unexpressible(const std::string& path, const std::string& why) {
    return make_error(ErrorCode::kInvalidArgument, "'" + path + "': a depfile cannot name this path (" + why + ")");
}
}  // namespace

Result<std::string> escape_depfile_path(const std::string& path) {
    if (path.empty()) return unexpressible(path, "empty");
    std::string out;
    out.reserve(path.size() + 8);
    for (size_t i = 0; i < path.size(); ++i) {
        const char c = path[i];
        const char next = i + 1 < path.size() ? path[i + 1] : '\0';
        switch (c) {
            case '\n':
            case '\r':
            case '\t':
            case '\0': return unexpressible(path, "it holds a newline, tab or NUL");
            case '\\':
                if (i + 1 == path.size()) return unexpressible(path, "it ends in a backslash");
                if (next == ' ' || next == '#' || next == ':')
                    return unexpressible(path, "a backslash before a space, '#' or ':'");
                out += c;
                break;
            case ' ': out += "\\ "; break;
            case '#': out += "\\#"; break;
            case '$': out += "$$"; break;
            case ':':
                if (i + 1 == path.size()) return unexpressible(path, "it ends in ':'");
                out += "\\:";
                break;
            default: out += c;
        }
    }
    return out;
}

Result<std::string> make_depfile(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
    if (outputs.empty()) return make_error(ErrorCode::kInvalidArgument, "depfile: the command wrote no file to name as its target");
    std::string text;
    for (size_t i = 0; i < outputs.size(); ++i) {
        auto e = escape_depfile_path(outputs[i]);
        if (!e) return e.error();
        text += (i ? " " : "") + *e;
    }
    text += ":";
    for (const std::string& in : inputs) {
        auto e = escape_depfile_path(in);
        if (!e) return e.error();
        text += " \\\n  " + *e;
    }
    text += "\n";
    return text;
}

}  // namespace zhc
