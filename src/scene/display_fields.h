// The scene's optional `display` block, one row per field: the loader (scene/load.cpp) reads
// the block and the saver (scene/save.cpp) writes it from this one table, so a field the
// saver records is a field the loader reads, with the same name and spelling.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/json_reader.h"
#include "scene/load.h"  // in_quotes
#include "scene/scene.h"

namespace kr {

// What reading one field found: nothing wrong, a value of the wrong kind (the loader fails
// at once), or a number out of range (clamped; the loader defers it as its range problems).
struct DisplayFieldRead {
    enum class Problem { none, wrong, range };
    Problem problem = Problem::none;
    std::string message;  // "expected ..., got ..." (empty when none)
};

struct DisplayField {
    std::string_view key;
    std::string expected;  // what the value must be, for "missing key" and error messages
    std::function<DisplayFieldRead(const Json& value, DisplaySettings& into)> read;
    // The value as the file spells it; nothing: the field is left out.
    std::function<std::optional<Json>(const DisplaySettings& from)> write;
};

namespace display_detail {

template <typename Enum, size_t N>
DisplayFieldRead read_name(const Json& v, const EnumNames<Enum, N>& names, std::string_view what, Enum& out) {
    const std::string what_text(what);
    if (!v.is_string()) return {DisplayFieldRead::Problem::wrong, "expected a " + what_text + " (a string), got " + describe(v)};
    const auto parsed = names.parse(v.get_ref<const std::string&>());
    if (!parsed)
        return {DisplayFieldRead::Problem::wrong,
                "unknown " + what_text + " " + in_quotes(v.get_ref<const std::string&>()) + "; expected " + names.list()};
    out = *parsed;
    return {};
}

inline std::string stops_text() {
    return "a number of stops in [-" + std::to_string(int(kMaxExposureStops)) + ", " +
           std::to_string(int(kMaxExposureStops)) + "]";
}

}  // namespace display_detail

inline const std::vector<DisplayField>& display_fields() {
    using display_detail::read_name;
    static const std::vector<DisplayField> fields = {
        {"tonemap", tonemap_names.list(),
         [](const Json& v, DisplaySettings& d) { return read_name(v, tonemap_names, "tone map", d.tonemap); },
         [](const DisplaySettings& d) { return std::optional<Json>(std::string(tonemap_names.name(d.tonemap))); }},
        {"exposure", display_detail::stops_text(),
         [](const Json& v, DisplaySettings& d) -> DisplayFieldRead {
             if (!v.is_number()) return {DisplayFieldRead::Problem::wrong, "expected a number, got " + describe(v)};
             const double ev = v.get<double>();
             // The parser already refuses overflowing literals; this keeps the promise local.
             if (!std::isfinite(ev)) return {DisplayFieldRead::Problem::wrong, "expected a finite number, got " + number_text(v)};
             d.exposure = std::clamp(ev, -kMaxExposureStops, kMaxExposureStops);
             if (std::abs(ev) > kMaxExposureStops)
                 return {DisplayFieldRead::Problem::range, "expected " + display_detail::stops_text() + ", got " + number_text(v)};
             return {};
         },
         [](const DisplaySettings& d) { return std::optional<Json>(d.exposure); }},
        {"denoise", denoise_names.list(),
         [](const Json& v, DisplaySettings& d) {
             Denoise mode = Denoise::off;
             DisplayFieldRead r = read_name(v, denoise_names, "denoise mode", mode);
             if (r.problem == DisplayFieldRead::Problem::none) d.denoise = mode;
             return r;
         },
         [](const DisplaySettings& d) {
             return d.denoise ? std::optional<Json>(std::string(denoise_names.name(*d.denoise))) : std::nullopt;
         }},
    };
    return fields;
}

}  // namespace kr
