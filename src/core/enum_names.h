// One name table per enum: the names a scene file, the command line and the viewer's
// combos use for an enum's values, and the list of them for error messages.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace kr {

template <typename Enum, size_t N>
struct EnumNames {
    std::array<std::string_view, N> names;

    std::string_view name(Enum e) const { return names[static_cast<size_t>(e)]; }
    std::optional<Enum> parse(std::string_view s) const {
        for (size_t i = 0; i < N; ++i)
            if (names[i] == s) return static_cast<Enum>(i);
        return std::nullopt;
    }
    // "a", "b" or "c": for error messages.
    std::string list() const {
        std::string out;
        for (size_t i = 0; i < N; ++i) {
            if (i > 0) out += (i + 1 == N) ? " or " : ", ";
            out += '"';
            out += names[i];
            out += '"';
        }
        return out;
    }
};

}  // namespace kr
