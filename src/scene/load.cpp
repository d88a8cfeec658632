// Strict scene loading: every problem becomes one SceneError naming the file, the JSON
// pointer and what was expected. Validation runs in three steps: the raw text (nesting
// depth), the JSON syntax (nlohmann, plus duplicate keys and non-finite numbers), then the
// scene format itself.
#include "scene/load.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <system_error>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <sys/stat.h>

#include "core/limits.h"
#include "core/memory.h"
#include "core/text.h"
#include "scene/display_fields.h"
#include "scene/json_reader.h"

namespace kr {

namespace {

std::string format_message(const std::string& file, const std::string& json_path,
                           const std::string& message) {
    // The root pointer is the empty string; "file: : message" would read like a typo. The
    // file name and the pointer (whose keys are the file's) are user text.
    if (json_path.empty()) return show_user_text(file) + ": " + message;
    return show_user_text(file) + ": " + show_user_text(json_path) + ": " + message;
}

}  // namespace

SceneError::SceneError(std::string file, std::string json_path, std::string message)
    : std::runtime_error(format_message(file, json_path, message)),
      file_(std::move(file)),
      json_path_(std::move(json_path)),
      message_(std::move(message)) {}

// User text in a message: quoted, escaped and bounded (core/text.h).
std::string in_quotes(std::string_view s) { return quote_user_text(s); }

namespace {

constexpr size_t kMaxListedIds = 10;

// ---------------------------------------------------------------------------------------
// The scene format

enum class Category { cameras, materials, shapes, lights, scene };

// Which object a deferred range problem belongs to: it is an error only if the scene
// block uses that object.
struct Owner {
    Category category;
    size_t index;
};

struct RangeProblem {
    Owner owner;
    std::string pointer, message;
};

// Ids of one category, for resolving references and listing the valid ones.
struct IdIndex {
    std::string singular;  // "material"
    std::string plural;    // "materials"
    std::unordered_map<std::string, size_t> by_id;
    std::vector<std::string> ids;
};

// One key an object may have: read is called with its value and pointer.
struct Field {
    std::string name;
    std::string expected;  // for "missing key" messages
    std::function<void(const Json&, const std::string&)> read;
    bool required = true;
};

class Loader {
public:
    explicit Loader(std::string file) : file_(std::move(file)) {
        cameras_ = {"camera", "cameras", {}, {}};
        materials_ = {"material", "materials", {}, {}};
        shapes_ = {"shape", "shapes", {}, {}};
        lights_ = {"light", "lights", {}, {}};
    }

    LoadedScene load(const Json& root);

private:
    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
        throw SceneError(file_, pointer, message);
    }
    void warn(const std::string& pointer, const std::string& message) {
        out_.warnings.push_back(format_message(file_, pointer, message));
    }
    void range_problem(Owner owner, const std::string& pointer, std::string message) {
        problems_.push_back({owner, pointer, std::move(message)});
    }

    // --- typed readers: structural problems fail at once, range problems are deferred
    void require_object(const Json& j, const std::string& pointer, std::string_view what) const;
    void read_fields(const Json& object, const std::string& pointer,
                     const std::vector<Field>& fields) const;
    double number(const Json& j, const std::string& pointer) const;
    double checked(const Json& j, const std::string& pointer, Owner owner,
                   std::string_view expected, bool (*ok)(double));
    double integer(const Json& j, const std::string& pointer, std::string_view expected) const;
    Vec3 vec3(const Json& j, const std::string& pointer) const;
    Color color(const Json& j, const std::string& pointer, Owner owner, bool reflectance);
    std::string nonempty_string(const Json& j, const std::string& pointer, std::string_view expected) const;
    size_t resolve(const IdIndex& index, const Json& j, const std::string& pointer) const;

    // An enum's value by its name table: `what` names it in messages ("camera type").
    template <typename Enum, size_t N>
    Enum read_enum(const Json& j, const std::string& pointer, const EnumNames<Enum, N>& names,
                   std::string_view what) const;
    template <typename Enum, size_t N>
    std::pair<std::string, Enum> header(const Json& j, const std::string& pointer,
                                        IdIndex* index, const EnumNames<Enum, N>& names,
                                        std::string_view kind);
    Field id_field() const { return {"id", "a non-empty string", [](const Json&, const std::string&) {}}; }
    Field type_field() const { return {"type", "a type name", [](const Json&, const std::string&) {}}; }

    template <typename Item>
    void read_category(const Json& root, std::string_view key, std::vector<Item>& items,
                       void (Loader::*read)(const Json&, const std::string&, size_t));
    void read_camera(const Json& j, const std::string& pointer, size_t index);
    void read_material(const Json& j, const std::string& pointer, size_t index);
    void read_shape(const Json& j, const std::string& pointer, size_t index);
    void read_light(const Json& j, const std::string& pointer, size_t index);
    void read_scene(const Json& j, const std::string& pointer);
    void read_primitive(const Json& j, const std::string& pointer);
    void read_renderer(const Json& j, const std::string& pointer);
    void read_display(const Json& j, const std::string& pointer);

    struct Usage {
        std::vector<bool> cameras, materials, shapes, lights;
    };
    Usage usage() const;
    void settle_range_problems();

    std::string file_;
    LoadedScene out_;
    IdIndex cameras_, materials_, shapes_, lights_;
    std::vector<RangeProblem> problems_;
};

void Loader::require_object(const Json& j, const std::string& pointer, std::string_view what) const {
    if (!j.is_object()) fail(pointer, "expected " + std::string(what) + " (a JSON object), got " + describe(j));
}

// Unknown keys first (in document order), then missing ones, then each value in
// document order.
void Loader::read_fields(const Json& object, const std::string& pointer,
                         const std::vector<Field>& fields) const {
    auto find = [&](const std::string& key) -> const Field* {
        for (const Field& f : fields)
            if (f.name == key) return &f;
        return nullptr;
    };
    for (const auto& [key, value] : object.items()) {
        if (find(key)) continue;
        std::vector<std::string> names;
        for (const Field& f : fields) names.push_back(f.name);
        fail(child(pointer, key), "unknown key " + in_quotes(key) + "; expected one of " + quoted_list(names));
    }
    for (const Field& f : fields)
        if (f.required && !object.contains(f.name))
            fail(pointer, "missing key " + in_quotes(f.name) + "; expected " + f.expected);
    for (const auto& [key, value] : object.items()) find(key)->read(value, child(pointer, key));
}

double Loader::number(const Json& j, const std::string& pointer) const {
    if (!j.is_number()) fail(pointer, "expected a number, got " + describe(j));
    const double v = j.get<double>();
    // The parser already refuses overflowing literals; this keeps the promise local.
    if (!std::isfinite(v)) fail(pointer, "expected a finite number, got " + number_text(j));
    return v;
}

double Loader::checked(const Json& j, const std::string& pointer, Owner owner,
                       std::string_view expected, bool (*ok)(double)) {
    const double v = number(j, pointer);
    if (!ok(v)) range_problem(owner, pointer, "expected " + std::string(expected) + ", got " + number_text(j));
    return v;
}

double Loader::integer(const Json& j, const std::string& pointer, std::string_view expected) const {
    if (!j.is_number()) fail(pointer, "expected " + std::string(expected) + ", got " + describe(j));
    const double v = number(j, pointer);
    if (std::floor(v) != v) fail(pointer, "expected " + std::string(expected) + ", got " + describe(j));
    return v;
}

Vec3 Loader::vec3(const Json& j, const std::string& pointer) const {
    if (!j.is_array() || j.size() != 3)
        fail(pointer, "expected an array of 3 finite numbers, got " + describe(j));
    const double x = number(j[0], child(pointer, size_t{0}));
    const double y = number(j[1], child(pointer, size_t{1}));
    const double z = number(j[2], child(pointer, size_t{2}));
    return {x, y, z};
}

Color Loader::color(const Json& j, const std::string& pointer, Owner owner, bool reflectance) {
    const Color c = vec3(j, pointer);
    bool warned = false;
    for (size_t i = 0; i < 3; ++i) {
        const std::string p = child(pointer, i);
        if (c[static_cast<int>(i)] < 0)
            range_problem(owner, p, "expected a value >= 0, got " + number_text(j[i]));
        else if (reflectance && c[static_cast<int>(i)] > 1 && !warned) {
            // Legal (the renderer copes), but almost always a typo, so say so.
            warn(p, "reflectance " + number_text(j[i]) + " is above 1: not energy conserving");
            warned = true;
        }
    }
    return c;
}

std::string Loader::nonempty_string(const Json& j, const std::string& pointer, std::string_view expected) const {
    if (!j.is_string() || j.get_ref<const std::string&>().empty())
        fail(pointer, "expected " + std::string(expected) + ", got " + describe(j));
    return j.get<std::string>();
}

size_t Loader::resolve(const IdIndex& index, const Json& j, const std::string& pointer) const {
    if (!j.is_string()) fail(pointer, "expected a " + index.singular + " id (a string), got " + describe(j));
    const std::string& id = j.get_ref<const std::string&>();
    if (auto it = index.by_id.find(id); it != index.by_id.end()) return it->second;
    std::string message = "no " + index.singular + " with id " + in_quotes(id);
    if (index.ids.empty())
        message += "; the file defines no " + index.plural;
    else if (index.ids.size() <= kMaxListedIds)
        message += "; expected one of " + quoted_list(index.ids);
    else
        message += " among the " + std::to_string(index.ids.size()) + " " + index.plural + " defined";
    fail(pointer, message);
}

template <typename Enum, size_t N>
Enum Loader::read_enum(const Json& j, const std::string& pointer, const EnumNames<Enum, N>& names,
                       std::string_view what) const {
    const std::string what_text(what);
    if (!j.is_string()) fail(pointer, "expected a " + what_text + " (a string), got " + describe(j));
    const auto parsed = names.parse(j.get_ref<const std::string&>());
    if (!parsed)
        fail(pointer, "unknown " + what_text + " " + in_quotes(j.get_ref<const std::string&>()) + "; expected " +
                          names.list());
    return *parsed;
}

// The id and type of a category entry: needed before its other keys can be checked.
template <typename Enum, size_t N>
std::pair<std::string, Enum> Loader::header(const Json& j, const std::string& pointer,
                                            IdIndex* index, const EnumNames<Enum, N>& names,
                                            std::string_view kind) {
    const std::string kind_text(kind);
    require_object(j, pointer, "a " + kind_text);
    if (!j.contains("id")) fail(pointer, "missing key \"id\"; expected a non-empty string");
    const std::string id = nonempty_string(j["id"], child(pointer, "id"), "a non-empty string id");
    if (!j.contains("type")) fail(pointer, "missing key \"type\"; expected " + names.list());
    const Enum type = read_enum(j["type"], child(pointer, "type"), names, kind_text + " type");
    if (index) {
        const size_t position = index->ids.size();
        const auto [it, inserted] = index->by_id.emplace(id, position);
        if (!inserted)
            fail(child(pointer, "id"), "duplicate " + index->singular + " id " + in_quotes(id) +
                                           ": also the id of /" + index->plural + "/" +
                                           std::to_string(it->second) +
                                           "; ids must be unique within " + in_quotes(index->plural));
        index->ids.push_back(id);
    }
    return {id, type};
}

template <typename Item>
void Loader::read_category(const Json& root, std::string_view key, std::vector<Item>& items,
                           void (Loader::*read)(const Json&, const std::string&, size_t)) {
    const std::string k(key);
    if (!root.contains(k)) return;  // an absent category is an empty one
    const Json& list = root[k];
    const std::string pointer = child("", key);
    if (!list.is_array()) fail(pointer, "expected an array of " + k + ", got " + describe(list));
    items.reserve(list.size());
    for (size_t i = 0; i < list.size(); ++i) (this->*read)(list[i], child(pointer, i), i);
}

void Loader::read_camera(const Json& j, const std::string& pointer, size_t index) {
    Camera cam;
    const Owner owner{Category::cameras, index};
    std::tie(cam.id, cam.type) = header(j, pointer, &cameras_, camera_type_names, "camera");
    std::vector<Field> fields = {
        id_field(),
        type_field(),
        {"fov", "a number in (0, 180) degrees",
         [&](const Json& v, const std::string& p) {
             cam.fov = checked(v, p, owner, "a field of view in (0, 180) degrees",
                               [](double x) { return x > 0 && x < 180; });
         }},
        {"aspect", "a number > 0",
         [&](const Json& v, const std::string& p) {
             cam.aspect = checked(v, p, owner, "an aspect ratio > 0", [](double x) { return x > 0; });
         }},
        {"distance", "a number > 0",
         [&](const Json& v, const std::string& p) {
             cam.distance = checked(v, p, owner, "a distance > 0", [](double x) { return x > 0; });
         },
         false},
        {"position", "an array of 3 finite numbers",
         [&](const Json& v, const std::string& p) { cam.position = vec3(v, p); }},
        {"target", "an array of 3 finite numbers",
         [&](const Json& v, const std::string& p) { cam.target = vec3(v, p); }},
    };
    if (cam.type == CameraType::lens) {
        fields.push_back({"focal distance", "a number > 0", [&](const Json& v, const std::string& p) {
                              cam.focal_distance = checked(v, p, owner, "a focal distance > 0",
                                                           [](double x) { return x > 0; });
                          }});
        fields.push_back({"alpha", "an aperture radius >= 0", [&](const Json& v, const std::string& p) {
                              cam.alpha = checked(v, p, owner, "an aperture radius >= 0",
                                                  [](double x) { return x >= 0; });
                          }});
    }
    read_fields(j, pointer, fields);
    // Without a view direction there is no camera frame.
    if (cam.position == cam.target) range_problem(owner, pointer, "camera position equals target; expected distinct points");
    out_.scene.cameras.push_back(std::move(cam));
}

// A material number's range as a missing key's message gives it: "in [0, 1)", "> 0".
std::string number_range_text(const MaterialParam& param) {
    auto text = [](double x) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", x);
        return std::string(buf);
    };
    if (std::isinf(param.hi)) return (param.lo_open ? "> " : ">= ") + text(param.lo);
    return std::string("in ") + (param.lo_open ? "(" : "[") + text(param.lo) + ", " + text(param.hi) +
           (param.hi_open ? ")" : "]");
}

void Loader::read_material(const Json& j, const std::string& pointer, size_t index) {
    Material mat;
    const Owner owner{Category::materials, index};
    std::tie(mat.id, mat.type) = header(j, pointer, &materials_, material_type_names, "material");
    std::vector<Field> fields = {id_field(), type_field()};
    for (const MaterialParam& param : material_params(mat.type)) {
        if (param.colour)
            fields.push_back({std::string(param.name), "an array of 3 numbers >= 0",
                              [&, t = &(mat.*param.colour)](const Json& v, const std::string& p) {
                                  *t = color(v, p, owner, true);
                              }});
        else
            fields.push_back({std::string(param.name), "a number " + number_range_text(param),
                              [&, t = &(mat.*param.number)](const Json& v, const std::string& p) {
                                  const double x = number(v, p);
                                  if (!param.in_range(x))
                                      range_problem(owner, p, "expected " + std::string(param.expected) +
                                                                  ", got " + number_text(v));
                                  *t = x;
                              }});
    }
    read_fields(j, pointer, fields);
    out_.scene.materials.push_back(std::move(mat));
}

void Loader::read_shape(const Json& j, const std::string& pointer, size_t index) {
    Shape shape;
    const Owner owner{Category::shapes, index};
    std::tie(shape.id, shape.type) = header(j, pointer, &shapes_, shape_type_names, "shape");
    read_fields(j, pointer,
                {id_field(), type_field(),
                 {"centre", "an array of 3 finite numbers",
                  [&](const Json& v, const std::string& p) { shape.centre = vec3(v, p); }},
                 {"radius", "a number > 0", [&](const Json& v, const std::string& p) {
                      shape.radius = checked(v, p, owner, "a radius > 0", [](double x) { return x > 0; });
                  }}});
    out_.scene.shapes.push_back(std::move(shape));
}

void Loader::read_light(const Json& j, const std::string& pointer, size_t index) {
    Light light;
    const Owner owner{Category::lights, index};
    std::tie(light.id, light.type) = header(j, pointer, &lights_, light_type_names, "light");
    std::vector<Field> fields = {id_field(), type_field()};
    for (const LightParam& param : light_params(light.type)) {
        std::function<void(const Json&, const std::string&)> read;
        switch (param.kind) {
        case LightFieldKind::vector:
            read = [&, t = &(light.*param.value)](const Json& v, const std::string& p) { *t = vec3(v, p); };
            break;
        case LightFieldKind::colour:
            read = [&, t = &(light.*param.value)](const Json& v, const std::string& p) {
                *t = color(v, p, owner, false);
            };
            break;
        case LightFieldKind::shape:
            read = [&, t = &(light.*param.shape)](const Json& v, const std::string& p) {
                *t = static_cast<int>(resolve(shapes_, v, p));
            };
            break;
        }
        fields.push_back({std::string(param.name), std::string(param.expected), std::move(read)});
    }
    read_fields(j, pointer, fields);
    out_.scene.lights.push_back(std::move(light));
}

// The lights an emissive primitive may carry, those whose row names a shape, in words:
// "an area light", or quoted as type names, "an \"area\" light".
std::string shape_light_words(bool quoted) {
    std::string names;
    for (size_t t = 0; t < light_type_names.names.size(); ++t) {
        if (!light_has_shape(LightType(t))) continue;
        const std::string name(light_type_names.names[t]);
        names += (names.empty() ? "" : " or ") + (quoted ? in_quotes(name) : name);
    }
    const bool vowel = names.find_first_of("aeiou") == (quoted ? 1 : 0);
    return (vowel ? "an " : "a ") + names + " light";
}

void Loader::read_primitive(const Json& j, const std::string& pointer) {
    Primitive prim;
    // Primitive ids may repeat (assignment_04 lists "floor" twice), so no index.
    std::tie(prim.id, prim.type) = header(j, pointer, nullptr, primitive_type_names, "primitive");
    std::vector<Field> fields = {
        id_field(),
        type_field(),
        {"shape", "a shape id",
         [&](const Json& v, const std::string& p) { prim.shape = static_cast<int>(resolve(shapes_, v, p)); }},
        {"material", "a material id",
         [&](const Json& v, const std::string& p) {
             prim.material = static_cast<int>(resolve(materials_, v, p));
         }},
    };
    if (prim.type == PrimitiveType::emissive)
        fields.push_back({"light", shape_light_words(false) + " id", [&](const Json& v, const std::string& p) {
                              const size_t l = resolve(lights_, v, p);
                              const Light& light = out_.scene.lights[l];
                              if (!light_has_shape(light.type))
                                  fail(p, "light " + in_quotes(light.id) + " is a " +
                                              in_quotes(light_type_names.name(light.type)) +
                                              " light; an emissive primitive expects " + shape_light_words(true));
                              prim.light = static_cast<int>(l);
                          }});
    read_fields(j, pointer, fields);
    out_.scene.primitives.push_back(std::move(prim));
}

void Loader::read_renderer(const Json& j, const std::string& pointer) {
    RendererSettings& r = out_.scene.renderer;
    const Owner owner{Category::scene, 0};
    require_object(j, pointer, "renderer settings");
    const std::string dimension_range = "an integer in [1, " + std::to_string(int(kMaxDimension)) + "]";
    const std::string samples_range = "an integer in [1, " + std::to_string(int(kMaxSamples)) + "]";
    read_fields(
        j, pointer,
        {{"type", renderer_type_names.list(),
          [&](const Json& v, const std::string& p) { r.type = read_enum(v, p, renderer_type_names, "renderer type"); }},
         {"dimensions", "an array of 2 integers [width, height]",
          [&](const Json& v, const std::string& p) {
              if (!v.is_array() || v.size() != 2)
                  fail(p, "expected an array of 2 integers [width, height], got " + describe(v));
              int* targets[2] = {&r.width, &r.height};
              for (size_t i = 0; i < 2; ++i) {
                  const std::string pi = child(p, i);
                  const double d = integer(v[i], pi, dimension_range);
                  if (d < 1 || d > kMaxDimension)
                      range_problem(owner, pi, "expected " + dimension_range + ", got " + number_text(v[i]));
                  // Clamped before the cast so an out-of-range double never overflows an int.
                  *targets[i] = static_cast<int>(std::clamp(d, 1.0, double(kMaxDimension)));
              }
          }},
         {"samples", samples_range,
          [&](const Json& v, const std::string& p) {
              const double s = integer(v, p, samples_range);
              if (s < 1 || s > kMaxSamples)
                  range_problem(owner, p, "expected " + samples_range + ", got " + number_text(v));
              r.samples = static_cast<int>(std::clamp(s, 1.0, double(kMaxSamples)));
          }},
         {"depth", "an integer >= 0",
          [&](const Json& v, const std::string& p) {
              const double d = integer(v, p, "an integer >= 0");
              if (d < 0) range_problem(owner, p, "expected an integer >= 0, got " + number_text(v));
              if (d > kMaxDepth)
                  warn(p, "depth " + number_text(v) + " is above the maximum " +
                              std::to_string(kMaxDepth) + "; clamped to " + std::to_string(kMaxDepth));
              r.depth = static_cast<int>(std::clamp(d, 0.0, double(kMaxDepth)));
          }},
         {"output", "a non-empty string (the output PPM path)",
          [&](const Json& v, const std::string& p) {
              r.output = nonempty_string(v, p, "a non-empty string (the output PPM path)");
              // A path ends at a NUL byte for the operating system: "a\u0000b" would write "a".
              if (r.output.find('\0') != std::string::npos)
                  fail(p, "expected a file path without NUL bytes (\\u0000), got " + in_quotes(r.output));
          }}});
}

void Loader::read_scene(const Json& j, const std::string& pointer) {
    Scene& scene = out_.scene;
    require_object(j, pointer, "the scene block");
    read_fields(
        j, pointer,
        {{"camera", "a camera id",
          [&](const Json& v, const std::string& p) { scene.camera = static_cast<int>(resolve(cameras_, v, p)); }},
         {"lights", "an array of light ids",
          [&](const Json& v, const std::string& p) {
              if (!v.is_array()) fail(p, "expected an array of light ids, got " + describe(v));
              // Where each light is listed: one lookup per entry, not a scan (10^5 lights).
              std::vector<size_t> listed_at(scene.lights.size(), v.size());
              for (size_t i = 0; i < v.size(); ++i) {
                  const int l = static_cast<int>(resolve(lights_, v[i], child(p, i)));
                  if (listed_at[size_t(l)] < v.size())
                      fail(child(p, i), "light " + in_quotes(scene.lights[size_t(l)].id) +
                                            " is already listed at " + child(p, listed_at[size_t(l)]) +
                                            "; expected each active light once");
                  listed_at[size_t(l)] = i;
                  scene.active_lights.push_back(l);
              }
          }},
         {"primitives", "an array of primitives",
          [&](const Json& v, const std::string& p) {
              if (!v.is_array()) fail(p, "expected an array of primitives, got " + describe(v));
              for (size_t i = 0; i < v.size(); ++i) read_primitive(v[i], child(p, i));
          }},
         {"renderer", "the renderer settings (an object)",
          [&](const Json& v, const std::string& p) { read_renderer(v, p); }},
         {"display", "the display settings (an object)",
          [&](const Json& v, const std::string& p) { read_display(v, p); }, false}});
}

// Optional: how the image is tone mapped and whether it is denoised, as `render` writes it
// and the viewer shows it. The fields are those of the table the saver writes from.
void Loader::read_display(const Json& j, const std::string& pointer) {
    DisplaySettings& d = out_.scene.display;
    const Owner owner{Category::scene, 0};
    require_object(j, pointer, "display settings");
    std::vector<Field> fields;
    for (const DisplayField& field : display_fields())
        fields.push_back({std::string(field.key), field.expected,
                          [&](const Json& v, const std::string& p) {
                              DisplayFieldRead r = field.read(v, d);
                              if (r.problem == DisplayFieldRead::Problem::wrong) fail(p, r.message);
                              if (r.problem == DisplayFieldRead::Problem::range) range_problem(owner, p, std::move(r.message));
                          },
                          false});
    read_fields(j, pointer, fields);
}

// Which objects the scene block uses: the active camera, the active lights, the
// primitives' shapes, materials and lights, and the shapes the lights used name.
Loader::Usage Loader::usage() const {
    const Scene& s = out_.scene;
    Usage used;
    used.cameras.assign(s.cameras.size(), false);
    used.materials.assign(s.materials.size(), false);
    used.shapes.assign(s.shapes.size(), false);
    used.lights.assign(s.lights.size(), false);
    if (s.camera >= 0) used.cameras[size_t(s.camera)] = true;
    for (int l : s.active_lights) used.lights[size_t(l)] = true;
    for (const Primitive& p : s.primitives) {
        used.shapes[size_t(p.shape)] = true;
        used.materials[size_t(p.material)] = true;
        if (p.light >= 0) used.lights[size_t(p.light)] = true;
    }
    for (size_t l = 0; l < s.lights.size(); ++l) {
        if (!used.lights[l]) continue;
        for (const LightParam& param : light_params(s.lights[l].type))
            if (param.kind == LightFieldKind::shape && s.lights[l].*param.shape >= 0)
                used.shapes[size_t(s.lights[l].*param.shape)] = true;
    }
    return used;
}

// Files keep unused variants, so a bad value only matters where the scene block uses it.
void Loader::settle_range_problems() {
    const Usage used = usage();
    for (const RangeProblem& problem : problems_) {
        const size_t i = problem.owner.index;
        bool referenced = true;
        switch (problem.owner.category) {
            case Category::scene: break;
            case Category::cameras: referenced = used.cameras[i]; break;
            case Category::materials: referenced = used.materials[i]; break;
            case Category::shapes: referenced = used.shapes[i]; break;
            case Category::lights: referenced = used.lights[i]; break;
        }
        if (referenced) fail(problem.pointer, problem.message);
        warn(problem.pointer, problem.message + " (unused by the scene block, so only a warning)");
    }
}

LoadedScene Loader::load(const Json& root) {
    if (!root.is_object()) fail("", "expected a JSON object at the top level, got " + describe(root));
    const std::vector<std::string> top_keys = {"cameras", "materials", "shapes", "lights", "scene"};
    for (const auto& [key, value] : root.items()) {
        if (std::find(top_keys.begin(), top_keys.end(), key) == top_keys.end())
            fail(child("", key), "unknown key " + in_quotes(key) + "; expected one of " + quoted_list(top_keys));
    }
    if (!root.contains("scene")) fail("", "missing key \"scene\"; expected the scene block (an object)");
    // Dependency order, not document order: area lights name shapes, the scene names all.
    read_category(root, "cameras", out_.scene.cameras, &Loader::read_camera);
    read_category(root, "materials", out_.scene.materials, &Loader::read_material);
    read_category(root, "shapes", out_.scene.shapes, &Loader::read_shape);
    read_category(root, "lights", out_.scene.lights, &Loader::read_light);
    read_scene(root["scene"], "/scene");
    settle_range_problems();
    return std::move(out_);
}

}  // namespace

LoadedScene parse_scene(std::string_view json_text, const std::filesystem::path& file) {
    const std::string name = file.string();
    Json root = parse_json(json_text, name);
    // Freed without allocating on every way out, the loaded scene's return included: by then
    // the scene and the DOM together may hold most of the memory there is.
    const ReleasedOnExit<Json> freed{root};
    try {
        LoadedScene loaded = Loader(name).load(root);
        loaded.scene.source_file = file;
        return loaded;
    } catch (const std::exception& e) {
        if (!is_out_of_memory(e)) throw;
        release(root);  // before the message's strings are allocated
        throw out_of_memory(name, json_text);
    }
}

std::string read_scene_text(const std::filesystem::path& file) {
    const std::string name = file.string();
    const std::string limit = std::to_string(kMaxSceneFileBytes) + " bytes (" + format_bytes(kMaxSceneFileBytes) + ")";
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(name.c_str(), "rb"), &std::fclose);
    if (!f) throw SceneError(name, "", "cannot open scene file: " + std::generic_category().message(errno));
    // A regular file's size is known before reading it; anything else (/dev/zero, a FIFO) is
    // read only up to the limit.
    struct stat info {};
    if (::fstat(::fileno(f.get()), &info) == 0) {
        if (S_ISDIR(info.st_mode)) throw SceneError(name, "", "cannot read scene file: it is a directory");
        if (S_ISREG(info.st_mode) && uint64_t(info.st_size) > kMaxSceneFileBytes)
            throw SceneError(name, "", "scene file of " + std::to_string(info.st_size) +
                                           " bytes; expected at most " + limit);
    }
    std::string text;
    char buffer[1 << 16];
    size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, f.get())) > 0) {
        if (text.size() + n > kMaxSceneFileBytes)
            throw SceneError(name, "", "scene file longer than " + limit + " (reading stopped there)");
        try {
            text.append(buffer, n);
        } catch (const std::bad_alloc&) {
            throw out_of_memory(name, text);
        }
    }
    if (std::ferror(f.get()))
        throw SceneError(name, "", "cannot read scene file: " + std::generic_category().message(errno));
    return text;
}

LoadedScene load_scene_file(const std::filesystem::path& file) { return parse_scene(read_scene_text(file), file); }

}  // namespace kr
