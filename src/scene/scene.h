// The authored scene: exactly what a scene file (and later the viewer) describes.
// Objects refer to each other by index into the category vectors. The renderer never
// reads this directly; prepare_scene (render/render_scene.h) builds the render scene from it.
#pragma once

#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/denoise_mode.h"
#include "core/enum_names.h"
#include "core/image.h"   // ToneMap
#include "core/limits.h"  // kMaxDepth, kMaxDimension, kMaxSamples
#include "core/math.h"

namespace kr {

enum class CameraType { pinhole, lens };
inline constexpr EnumNames<CameraType, 2> camera_type_names{{"pinhole", "lens-based"}};

enum class MaterialType { diffuse, specular, glossy, dielectric, translucent };
inline constexpr EnumNames<MaterialType, 5> material_type_names{
    {"diffuse", "specular reflection", "glossy reflection", "fresnel dielectric",
     "translucent dielectric"}};

enum class ShapeType { sphere };
inline constexpr EnumNames<ShapeType, 1> shape_type_names{{"sphere"}};

enum class LightType { point, area };
inline constexpr EnumNames<LightType, 2> light_type_names{{"point", "area"}};

enum class PrimitiveType { geometric, emissive };
inline constexpr EnumNames<PrimitiveType, 2> primitive_type_names{{"geometric", "emissive"}};

enum class RendererType { wrt, pt };
inline constexpr EnumNames<RendererType, 2> renderer_type_names{{"WRT", "PT"}};

struct Camera {
    std::string id;
    CameraType type = CameraType::pinhole;
    double fov = 45;       // vertical field of view, degrees
    double aspect = 1;     // width / height of the image plane
    double distance = 5;   // image-plane distance (does not change the image of a pinhole)
    Vec3 position{0, 0, -15};
    Vec3 target{0, 0, 0};
    double focal_distance = 10;  // lens-based only: distance of the plane in focus
    double alpha = 0;            // lens-based only: aperture radius
};

struct Material {
    std::string id;
    MaterialType type = MaterialType::diffuse;
    Color rho{0.8};       // diffuse, specular reflection, glossy reflection
    Color rho_r{1};       // dielectrics: reflected fraction ("rhoR")
    Color rho_t{1};       // dielectrics: transmitted fraction ("rhoT")
    double eta = 1.5;     // dielectrics: refractive index inside / outside
    double roughness = 0; // glossy reflection, translucent dielectric: beta in [0, 1)
};

// One parameter of a material type as the file names it, read by the loader, the saver and
// the viewer's Materials panel: the member it sets, what the file may hold, and the panel's
// slider. A colour is three reflectances >= 0 (above 1 warns); a number lies in
// [lo, hi], with either end open.
struct MaterialParam {
    std::string_view name;                 // "rho", "rhoR", "eta", ...
    Color Material::*colour = nullptr;     // a colour parameter, or
    double Material::*number = nullptr;    // a number parameter
    std::string_view expected;             // a number's range in words: "a roughness in [0, 1)"
    double lo = 0, hi = 0;
    bool lo_open = false, hi_open = false;
    double edit_lo = 0, edit_hi = 1;       // the panel's slider range
    float edit_speed = 0.005f;             // and its step per pixel dragged

    bool in_range(double x) const { return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi); }
};

namespace material_param_rows {

constexpr MaterialParam colour_param(std::string_view name, Color Material::*member) {
    MaterialParam p;
    p.name = name;
    p.colour = member;
    return p;
}
constexpr MaterialParam number_param(std::string_view name, double Material::*member, std::string_view expected,
                                     double lo, double hi, bool lo_open, bool hi_open, double edit_lo,
                                     double edit_hi, float edit_speed) {
    MaterialParam p;
    p.name = name;
    p.number = member;
    p.expected = expected;
    p.lo = lo, p.hi = hi, p.lo_open = lo_open, p.hi_open = hi_open;
    p.edit_lo = edit_lo, p.edit_hi = edit_hi, p.edit_speed = edit_speed;
    return p;
}

inline constexpr MaterialParam kRho = colour_param("rho", &Material::rho);
inline constexpr MaterialParam kRhoR = colour_param("rhoR", &Material::rho_r);
inline constexpr MaterialParam kRhoT = colour_param("rhoT", &Material::rho_t);
inline constexpr MaterialParam kRoughness = number_param("roughness", &Material::roughness, "a roughness in [0, 1)",
                                                         0, 1, false, true, 0, 0.999, 0.002f);
inline constexpr MaterialParam kEta =
    number_param("eta", &Material::eta, "a refractive index eta > 0", 0, std::numeric_limits<double>::infinity(),
                 true, false, 1.0 / 4, 4, 0.002f);

inline constexpr MaterialParam kRhoOnly[] = {kRho};
inline constexpr MaterialParam kGlossy[] = {kRho, kRoughness};
inline constexpr MaterialParam kDielectric[] = {kRhoR, kRhoT, kEta};
inline constexpr MaterialParam kTranslucent[] = {kRhoR, kRhoT, kEta, kRoughness};

}  // namespace material_param_rows

// The parameters of a material type, in the file's order.
constexpr std::span<const MaterialParam> material_params(MaterialType type) {
    using namespace material_param_rows;
    switch (type) {
    case MaterialType::diffuse:
    case MaterialType::specular: return kRhoOnly;
    case MaterialType::glossy: return kGlossy;
    case MaterialType::dielectric: return kDielectric;
    case MaterialType::translucent: return kTranslucent;
    }
    return {};
}

// The colour or number members (T: Color or double) that any type's parameters name, each
// once, in the order of the types and their parameters: the SIMD lanes keep a per-sphere
// column of each (render/lanes/tables.h), so a new parameter needs no reader of its own.
template <class T>
struct MaterialMembers {
    std::array<T Material::*, 8> members{};
    size_t count = 0;
    // The member's place in `members` (count where it is not there).
    constexpr size_t index(T Material::*member) const {
        for (size_t i = 0; i < count; ++i)
            if (members[i] == member) return i;
        return count;
    }
};
template <class T>
constexpr MaterialMembers<T> material_members(T Material::*MaterialParam::*field) {
    MaterialMembers<T> out;
    for (size_t t = 0; t < material_type_names.names.size(); ++t)
        for (const MaterialParam& param : material_params(MaterialType(t)))
            if (param.*field && out.index(param.*field) == out.count) out.members[out.count++] = param.*field;
    return out;
}
inline constexpr MaterialMembers<Color> kMaterialColours = material_members<Color>(&MaterialParam::colour);
inline constexpr MaterialMembers<double> kMaterialNumbers = material_members<double>(&MaterialParam::number);

struct Shape {
    std::string id;
    ShapeType type = ShapeType::sphere;
    Vec3 centre{};
    double radius = 1;
};

struct Light {
    std::string id;
    LightType type = LightType::point;
    Vec3 position{};  // point only
    Color power{1};   // point: radiant intensity; area: emitted radiance
    int shape = -1;   // area only: index into Scene::shapes
};

// One field of a light type as the file names it, read by the loader, written by the saver
// and shown by the viewer's Lights and Selection panels: what kind of value it holds, the
// member it sets, the words a missing key's message says, and the panel's step.
enum class LightFieldKind {
    vector,  // three finite numbers (a position, a direction)
    colour,  // three numbers >= 0 (a power)
    shape,   // a shape's id in the file, an index into Scene::shapes here
};
struct LightParam {
    std::string_view name;            // "position", "shape", "power"
    LightFieldKind kind = LightFieldKind::vector;
    Vec3 Light::*value = nullptr;     // a vector's or a colour's member (Color is Vec3)
    int Light::*shape = nullptr;      // a shape reference's member
    std::string_view expected;        // a missing key's words: "an array of 3 finite numbers"
    // Where the light is: its point (a vector) or its sphere (a shape reference); a light
    // with no such field (one at infinity) is nowhere in the scene (light_anchor).
    bool anchor = false;
    float edit_speed = 0.1f;          // the panel's step per pixel dragged
};

namespace light_param_rows {

constexpr LightParam vector_param(std::string_view name, Vec3 Light::*member, bool anchor, float edit_speed) {
    return {.name = name, .kind = LightFieldKind::vector, .value = member, .expected = "an array of 3 finite numbers",
            .anchor = anchor, .edit_speed = edit_speed};
}
constexpr LightParam colour_param(std::string_view name, Color Light::*member, float edit_speed) {
    return {.name = name, .kind = LightFieldKind::colour, .value = member, .expected = "an array of 3 numbers >= 0",
            .edit_speed = edit_speed};
}
// A shape reference is where its light is.
constexpr LightParam shape_param(std::string_view name, int Light::*member) {
    return {.name = name, .kind = LightFieldKind::shape, .shape = member, .expected = "a shape id", .anchor = true};
}

// A point light: where it is and its radiant intensity.
inline constexpr LightParam kPoint[] = {vector_param("position", &Light::position, true, 0.02f),
                                        colour_param("power", &Light::power, 0.5f)};
// An area light: the sphere that emits (carried by an emissive primitive over the same
// shape) and its emitted radiance.
inline constexpr LightParam kArea[] = {shape_param("shape", &Light::shape), colour_param("power", &Light::power, 0.1f)};

}  // namespace light_param_rows

// The fields of a light type, in the file's order.
constexpr std::span<const LightParam> light_params(LightType type) {
    using namespace light_param_rows;
    switch (type) {
    case LightType::point: return kPoint;
    case LightType::area: return kArea;
    }
    return {};
}

// Whether a light of this type is a shape's surface, which an emissive primitive carries
// (its row names a shape).
constexpr bool light_has_shape(LightType type) {
    for (const LightParam& param : light_params(type))
        if (param.kind == LightFieldKind::shape) return true;
    return false;
}

// The type of the light the viewer gives a primitive made emissive: the first with a shape.
inline constexpr LightType kShapeLightType = [] {
    for (size_t t = 0; t < light_type_names.names.size(); ++t)
        if (light_has_shape(LightType(t))) return LightType(t);
    return LightType::area;
}();

// Where a light is, from its row's anchor field: a point, a shape (an index into
// Scene::shapes, possibly -1 in a scene built in code), or nowhere (no anchor field).
struct LightAnchor {
    enum class Kind { none, point, shape };
    Kind kind = Kind::none;
    Vec3 point{};
    int shape = -1;
};
constexpr LightAnchor light_anchor(const Light& light) {
    for (const LightParam& param : light_params(light.type)) {
        if (!param.anchor) continue;
        if (param.kind == LightFieldKind::shape) return {LightAnchor::Kind::shape, Vec3{}, light.*param.shape};
        return {LightAnchor::Kind::point, light.*param.value, -1};
    }
    return {};
}

struct Primitive {
    std::string id;
    PrimitiveType type = PrimitiveType::geometric;
    int shape = -1;     // index into Scene::shapes
    int material = -1;  // index into Scene::materials
    int light = -1;     // emissive only: index into Scene::lights
};

struct RendererSettings {
    RendererType type = RendererType::pt;
    int width = 512, height = 512;
    int samples = 1;
    int depth = 6;       // maximum ray depth, at most kMaxDepth
    std::string output;  // as written in the file: relative to the scene file's folder
};

// How the image is shown and written: the optional `scene.display` block. The exposure is
// in stops (EV): radiance is scaled by 2^exposure before the tone map, so 0 leaves it as is.
inline constexpr double kMaxExposureStops = 10;
struct DisplaySettings {
    ToneMap tonemap = kDefaultToneMap;
    double exposure = 0;  // EV, in [-kMaxExposureStops, kMaxExposureStops]
    // Whether the image is developed denoised; absent: as each command does by default
    // (render: the raw estimate; the viewer: denoised).
    std::optional<Denoise> denoise;
    double exposure_scale() const { return std::exp2(exposure); }
};

// The whole file. Unreferenced cameras, materials, shapes and lights are kept (so the
// viewer can offer them and save the file back) but only the `scene` block is rendered.
struct Scene {
    std::vector<Camera> cameras;
    std::vector<Material> materials;
    std::vector<Shape> shapes;
    std::vector<Light> lights;

    int camera = -1;                  // active camera, index into cameras
    std::vector<int> active_lights;   // indices into lights
    std::vector<Primitive> primitives;
    RendererSettings renderer;
    DisplaySettings display;

    std::filesystem::path source_file;  // where it was loaded from (empty if built in code)

    // Output path resolved against the scene file's folder.
    std::filesystem::path output_path() const;
};

}  // namespace kr
