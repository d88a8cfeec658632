// The hardened JSON reader under the scene loader (load.cpp): parse_json turns a scene file's
// text into a DOM or one SceneError naming the file and, where it can, the JSON pointer; and
// the small helpers the loader's messages use.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene/load.h"

namespace kr {

// ordered_json keeps keys in document order, so "the first error" is the first in the file.
using Json = nlohmann::ordered_json;

// A child's JSON pointer (RFC 6901: only '~' and '/' are escaped).
std::string child(const std::string& pointer, std::string_view key);
std::string child(const std::string& pointer, size_t index);
// "a", "b", "c": the form used for lists of keys and ids.
std::string quoted_list(const std::vector<std::string>& items);
// A number as the file wrote it.
std::string number_text(const Json& j);
// What a value is, for "expected X, got Y" messages.
std::string describe(const Json& j);

// The DOM of `text`, or a SceneError: nesting deeper than 64 levels, a syntax error (with its
// line and column), a duplicate key or a number that overflows (with its pointer), or not
// enough memory.
Json parse_json(std::string_view text, const std::string& file);
// Frees a DOM without allocating (for when memory ran out).
void release(Json& j);
// The error for a scene whose DOM did not fit in memory.
SceneError out_of_memory(const std::string& file, std::string_view text);

}  // namespace kr
