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
// Frees a DOM without allocating. nlohmann's destructor does allocate: it first moves a
// container's children onto a heap stack (to avoid recursion), so destroying a DOM when
// memory has run out throws bad_alloc out of a noexcept destructor, and the process aborts
// (std::terminate). Popping children from the back allocates nothing; the recursion is as
// deep as the DOM's nesting, which parse_json bounds to 64 levels (and the savers' DOMs are
// a few levels deep).
template <class J>
void release(J& j) noexcept {
    if (j.is_array()) {
        auto& array = j.template get_ref<typename J::array_t&>();
        while (!array.empty()) {
            release(array.back());
            array.pop_back();
        }
    } else if (j.is_object()) {
        auto& object = j.template get_ref<typename J::object_t&>();
        while (!object.empty()) {
            if constexpr (requires { object.back(); }) {
                release(object.back().second);  // ordered_json: a vector of pairs
                object.pop_back();
            } else {
                auto last = std::prev(object.end());  // json: a std::map
                release(last->second);
                object.erase(last);
            }
        }
    }
}

// Holds a DOM (or one value being built) and frees it with release() whichever way its scope
// is left: every DOM that may be large, and every value built while memory may run out, is
// declared as one, so that no nlohmann destructor meets a non-empty container.
template <class J>
struct ReleasedOnExit {
    J& json;
    ~ReleasedOnExit() { release(json); }
};
// The error for a scene whose DOM did not fit in memory.
SceneError out_of_memory(const std::string& file, std::string_view text);

}  // namespace kr
