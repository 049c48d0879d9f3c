// Internal to the mesh module: the blank-separated tokens of one line of a
// text mesh format (OBJ, ASCII STL), shared by their readers.
#pragma once

#include <string_view>
#include <vector>

namespace surfmap {

// Splits `line` on spaces, tabs and carriage returns (a CRLF file's lines end
// in '\r'); never returns an empty token.
std::vector<std::string_view> BlankSeparatedTokens(std::string_view line);

}  // namespace surfmap
