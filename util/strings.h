// Small string chores shared by the parser, the command line and the service.
#pragma once

#include <string>
#include <string_view>

namespace vrl::util {

// ASCII lower case (scene names and keywords are ASCII; other bytes pass through).
std::string toLower(std::string_view text);

// `text` for an error message or a log line: itself when at most `max` bytes,
// else its first `max` bytes and "... (N bytes)". Keeps what a caller sent
// (an id, a name) from blowing up a message past a size limit.
std::string abbreviate(std::string_view text, size_t max = 64);

}  // namespace vrl::util
