#include "viewer/outliner.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include "viewer/scene_edit.h"

namespace kr::viewer {

OutlinerRow outliner_row(const Scene& scene, OutlinerKind kind, int index) {
    OutlinerRow row{kind, index, {}, {}};
    if (kind == OutlinerKind::object) {
        const Primitive& prim = scene.primitives[size_t(index)];
        row.label = primitive_label(scene, index);
        if (prim.material >= 0) {
            const Material& m = scene.materials[size_t(prim.material)];
            row.detail = std::string(material_type_names.name(m.type)) + " '" + m.id + "'";
        }
    } else if (kind == OutlinerKind::light) {
        const bool on = std::find(scene.active_lights.begin(), scene.active_lights.end(), index) != scene.active_lights.end();
        row.label = light_label(scene.lights[size_t(index)]);
        row.detail = on ? "on" : "off";
    } else {
        const Camera& cam = scene.cameras[size_t(index)];
        const std::string type(camera_type_names.name(cam.type));
        row.label = cam.id == type ? cam.id : cam.id + " (" + type + ")";
        if (index == scene.camera) row.detail = "active";
    }
    return row;
}

int outliner_count(const Scene& scene, OutlinerKind kind) {
    return int(kind == OutlinerKind::object  ? scene.primitives.size()
               : kind == OutlinerKind::light ? scene.lights.size()
                                             : scene.cameras.size());
}

std::vector<OutlinerRow> outliner_rows(const Scene& scene) {
    std::vector<OutlinerRow> rows;
    for (const OutlinerKind kind : {OutlinerKind::object, OutlinerKind::light, OutlinerKind::camera})
        for (int i = 0; i < outliner_count(scene, kind); ++i) rows.push_back(outliner_row(scene, kind, i));
    return rows;
}

bool outliner_row_matches(const OutlinerRow& row, std::string_view filter) {
    const size_t first = filter.find_first_not_of(' '), last = filter.find_last_not_of(' ');
    if (first == std::string_view::npos) return true;
    filter = filter.substr(first, last - first + 1);
    auto lower = [](unsigned char c) { return char(std::tolower(c)); };
    auto contains = [&](const std::string& text) {
        return std::search(text.begin(), text.end(), filter.begin(), filter.end(),
                           [&](char a, char b) { return lower(a) == lower(b); }) != text.end();
    };
    return contains(row.label) || contains(row.detail);
}

Selection row_selection(const Scene& scene, const OutlinerRow& row) {
    Selection s;
    if (row.kind == OutlinerKind::object) s.primitive = row.index;
    if (row.kind == OutlinerKind::light) {
        for (int p = 0; p < int(scene.primitives.size()) && !s.primitive; ++p)
            if (scene.primitives[size_t(p)].type == PrimitiveType::emissive && scene.primitives[size_t(p)].light == row.index)
                s.primitive = p;
        if (!s.primitive) s.light = row.index;
    }
    return s;
}

std::optional<Ball> selection_ball(const Scene& scene, const Selection& selection) {
    if (selection.primitive) {
        const int p = *selection.primitive;
        if (p < 0 || size_t(p) >= scene.primitives.size()) return std::nullopt;
        const int shape = scene.primitives[size_t(p)].shape;
        if (shape < 0 || size_t(shape) >= scene.shapes.size()) return std::nullopt;
        return Ball{scene.shapes[size_t(shape)].centre, scene.shapes[size_t(shape)].radius};
    }
    if (selection.light) {
        const int l = *selection.light;
        if (l < 0 || size_t(l) >= scene.lights.size()) return std::nullopt;
        const LightAnchor anchor = light_anchor(scene.lights[size_t(l)]);
        if (anchor.kind == LightAnchor::Kind::point) return Ball{anchor.point, 0};
        if (anchor.kind == LightAnchor::Kind::shape && anchor.shape >= 0 && size_t(anchor.shape) < scene.shapes.size())
            return Ball{scene.shapes[size_t(anchor.shape)].centre, scene.shapes[size_t(anchor.shape)].radius};
    }
    return std::nullopt;
}

Camera framed(const Camera& camera, const Ball& ball) {
    Camera c = camera;
    Vec3 forward = camera.target - camera.position;
    double distance = length(forward);
    forward = distance > 0 ? forward / distance : Vec3(0, 0, 1);
    if (ball.radius > 0) {
        // The narrower half angle: the vertical one (fov), or the horizontal one for a tall image.
        const double half_v = camera.fov * std::numbers::pi / 360;
        const double half = std::min(half_v, std::atan(std::tan(half_v) * camera.aspect));
        // A ball of radius r at distance d subtends asin(r / d) about its centre's ray.
        distance = ball.radius / std::sin(kFrameFill * half);
    } else if (!(distance > 0)) {
        distance = 1;
    }
    c.target = ball.centre;
    c.position = ball.centre - forward * distance;
    if (c.type == CameraType::lens) c.focal_distance = distance;
    return c;
}

Camera axis_view(const Camera& camera, AxisView view) {
    static constexpr Vec3 kFrom[] = {{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    Camera c = camera;
    double distance = length(camera.target - camera.position);
    if (!(distance > 0)) distance = 1;
    c.position = camera.target + kFrom[int(view)] * distance;
    return c;
}

const char* axis_view_name(AxisView view) {
    static constexpr const char* kNames[] = {"front", "back", "right", "left", "top", "bottom"};
    return kNames[int(view)];
}

int material_users(const Scene& scene, int m) {
    return int(std::count_if(scene.primitives.begin(), scene.primitives.end(), [&](const Primitive& p) { return p.material == m; }));
}

int own_material(Scene& scene, int p) {
    const int m = scene.primitives[size_t(p)].material;
    if (m < 0 || material_users(scene, m) > 1) new_material_for(scene, p);
    return scene.primitives[size_t(p)].material;
}

bool recolour_primitive(Scene& scene, int p, const Color& colour) {
    const int current = scene.primitives[size_t(p)].material;
    const MaterialType type = current >= 0 ? scene.materials[size_t(current)].type : MaterialType::diffuse;
    // The material's tint: its last colour parameter (rho, or a dielectric's transmitted rhoT).
    Color Material::*tint = nullptr;
    for (const MaterialParam& param : material_params(type))
        if (param.colour) tint = param.colour;
    if (!tint) return false;
    const int m = own_material(scene, p);
    scene.materials[size_t(m)].*tint = colour;
    return true;
}

}  // namespace kr::viewer
