// SceneError: a problem with a scene the user can fix (malformed XML, unknown
// plugin, bad value, missing mesh). The message names the file, line and
// element, and where useful lists the valid alternatives.
#pragma once

#include <stdexcept>
#include <string>

namespace vrl {

// Where something was declared in a scene file (line is 1-based; 0 if unknown).
struct SourceLocation {
    std::string file;
    int line = 0;
    std::string element;  // e.g. "<shape type=\"obj\">"

    std::string describe() const {
        std::string out = file.empty() ? std::string("<scene>") : file;
        if (line > 0) out.append(":").append(std::to_string(line));
        if (!element.empty()) out.append(": in ").append(element);
        return out;
    }
};

class SceneError : public std::runtime_error {
public:
    SceneError(const SourceLocation& where, const std::string& problem)
        : std::runtime_error(where.describe() + ": " + problem), where_(where) {}
    const SourceLocation& where() const { return where_; }

private:
    SourceLocation where_;
};

}  // namespace vrl
