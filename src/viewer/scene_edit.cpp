#include "viewer/scene_edit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "core/text.h"

namespace kr::viewer {

void set_light_on(Scene& scene, int index, bool on) {
    std::vector<int>& active = scene.active_lights;
    const auto it = std::find(active.begin(), active.end(), index);
    if (on && it == active.end()) active.push_back(index);
    if (!on && it != active.end()) active.erase(it);
}

std::string light_unseen_reason(const Scene& scene, int index) {
    const Light& light = scene.lights[size_t(index)];
    if (!(max_component(light.power) > 0)) return "its power is 0: it emits nothing";
    // The point (or sphere) that emits, and the primitive that carries a light on a shape;
    // a light with no place in the scene (scene.h's light_anchor) is inside no sphere.
    const LightAnchor anchor = light_anchor(light);
    if (anchor.kind == LightAnchor::Kind::none) return {};
    Vec3 at = anchor.point;
    double radius = 0;
    int carrier = -1;
    if (anchor.kind == LightAnchor::Kind::shape) {
        for (size_t i = 0; i < scene.primitives.size() && carrier < 0; ++i)
            if (scene.primitives[i].type == PrimitiveType::emissive && scene.primitives[i].light == index)
                carrier = int(i);
        if (carrier < 0) return "no primitive of the scene carries it: it emits nothing";
        const Shape& s = scene.shapes[size_t(scene.primitives[size_t(carrier)].shape)];
        at = s.centre;
        radius = s.radius;
    }
    const Vec3 eye = scene.cameras.empty() ? Vec3(0, 0, 0) : scene.cameras[size_t(scene.camera)].position;
    for (size_t i = 0; i < scene.primitives.size(); ++i) {
        if (int(i) == carrier) continue;
        const Shape& s = scene.shapes[size_t(scene.primitives[i].shape)];
        const bool holds_light = length(at - s.centre) + radius < s.radius;
        const bool holds_eye = length(eye - s.centre) < s.radius;
        if (holds_light && !holds_eye)
            return "it is inside the sphere of " + quote_user_text(scene.primitives[i].id) +
                   ", which the camera is outside: its light does not leave that sphere";
    }
    return {};
}

std::string primitive_label(const Scene& scene, int p) {
    const Primitive& prim = scene.primitives[size_t(p)];
    std::string label = prim.id;
    if (prim.shape >= 0 && scene.shapes[size_t(prim.shape)].id != prim.id)
        label += " (shape " + scene.shapes[size_t(prim.shape)].id + ")";
    if (prim.type == PrimitiveType::emissive) label += ", emissive";
    return label;
}

std::string light_label(const Light& light) {
    const std::string type(light_type_names.name(light.type));
    if (light.id.find(type) != std::string::npos) return light.id;
    return light.id + " (" + type + " light)";
}

std::optional<int> pick_primitive(const Scene& scene, const CameraModel& camera, double fx, double fy) {
    CameraModel pinhole = camera;
    pinhole.lens_radius = 0;
    const CameraRay ray = pinhole.generate(fx, fy, 0.5, 0.5);
    std::optional<int> best;
    double best_t = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < scene.primitives.size(); ++i) {
        const int si = scene.primitives[i].shape;
        if (si < 0) continue;
        const Shape& s = scene.shapes[size_t(si)];
        // |o + t d - c|^2 = r^2 with |d| = 1: the nearest t > 0.
        const Vec3 oc = ray.origin - s.centre;
        const double b = dot(oc, ray.direction), c = dot(oc, oc) - s.radius * s.radius;
        const double disc = b * b - c;
        if (disc < 0) continue;
        const double root = std::sqrt(disc);
        double t = -b - root;
        if (t <= 1e-9 * (1 + std::abs(b))) t = -b + root;
        if (t > 1e-9 * (1 + std::abs(b)) && t < best_t) {
            best_t = t;
            best = int(i);
        }
    }
    return best;
}

std::optional<ImageCircle> project_sphere(const CameraModel& camera, const Vec3& centre, double radius) {
    const Vec3 p = centre - camera.position;
    const double z = dot(p, camera.forward);
    if (!(z > 0)) return std::nullopt;
    // The inverse of the pinhole's image point to direction (fy grows downwards).
    ImageCircle c;
    c.fx = 0.5 + 0.5 * dot(p, camera.right) / (z * camera.tan_half_fov * camera.aspect);
    c.fy = 0.5 - 0.5 * dot(p, camera.up) / (z * camera.tan_half_fov);
    // The silhouette's angular radius asin(r / d), as a fraction of the image height.
    const double d = length(p);
    const double angle = radius < d ? std::asin(radius / d) : kPi / 2;
    c.radius = 0.5 * std::tan(std::min(angle, 1.5)) / camera.tan_half_fov;
    return c;
}

namespace {

// A point's image point, when it is in front of the camera.
std::optional<std::pair<double, double>> image_point(const CameraModel& camera, const Vec3& point) {
    const Vec3 p = point - camera.position;
    const double z = dot(p, camera.forward);
    if (!(z > 0)) return std::nullopt;
    return std::make_pair(0.5 + 0.5 * dot(p, camera.right) / (z * camera.tan_half_fov * camera.aspect),
                          0.5 - 0.5 * dot(p, camera.up) / (z * camera.tan_half_fov));
}

}  // namespace

std::vector<std::pair<double, double>> sphere_outline(const CameraModel& camera, const Vec3& centre, double radius,
                                                      int n) {
    // The silhouette is the circle of tangent points: centre c + (r^2 / d^2)(eye - c), radius
    // r sqrt(d^2 - r^2) / d, in the plane perpendicular to the view of the centre.
    const Vec3 to_eye = camera.position - centre;
    const double d2 = dot(to_eye, to_eye);
    std::vector<std::pair<double, double>> out;
    if (!(d2 > radius * radius)) return out;
    const Vec3 w = to_eye / std::sqrt(d2);
    const Vec3 ring_centre = centre + to_eye * (radius * radius / d2);
    const double ring = radius * std::sqrt(d2 - radius * radius) / std::sqrt(d2);
    Vec3 u = cross(w, std::abs(w.y) < 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0));
    u = u / length(u);
    const Vec3 v = cross(w, u);
    for (int i = 0; i < n; ++i) {
        const double a = 2 * kPi * i / n;
        const auto p = image_point(camera, ring_centre + (u * std::cos(a) + v * std::sin(a)) * ring);
        if (!p) return {};
        out.push_back(*p);
    }
    return out;
}

bool outline_on_image(const std::vector<std::pair<double, double>>& outline) {
    if (outline.empty()) return false;
    for (const auto& [fx, fy] : outline)
        if (!(fx >= 0 && fx <= 1 && fy >= 0 && fy <= 1)) return false;
    return true;
}

std::vector<unsigned char> sphere_coverage(const RenderScene& scene, const Vec3& centre, double radius, int cols,
                                           int rows) {
    std::vector<unsigned char> cells(size_t(std::max(0, cols)) * size_t(std::max(0, rows)), 0);
    CameraModel pinhole = scene.camera;
    pinhole.lens_radius = 0;  // the ray through the lens centre, as picking casts it
    for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) {
            const CameraRay cr = pinhole.generate((x + 0.5) / cols, (y + 0.5) / rows, 0.5, 0.5);
            Ray ray;
            ray.o = cr.origin;
            ray.d = cr.direction;
            Hit hit;
            if (!scene.intersects(ray, hit) || hit.sphere < 0) continue;
            // The render scene merges repeated primitives: the sphere seen is the selection's
            // when it is the same sphere.
            const SphereGeom& s = scene.spheres[size_t(hit.sphere)];
            cells[size_t(y) * size_t(cols) + size_t(x)] = s.centre == centre && s.radius == radius;
        }
    return cells;
}

Vec3 drag_offset(const CameraModel& camera, const Vec3& centre, double dx_pixels, double dy_pixels, int image_height,
                 int axis) {
    const double depth = std::max(1e-9, dot(centre - camera.position, camera.forward));
    const double per_pixel = 2.0 * depth * camera.tan_half_fov / std::max(1, image_height);
    Vec3 move = camera.right * (dx_pixels * per_pixel) - camera.up * (dy_pixels * per_pixel);
    if (axis >= 0 && axis < 3) {
        // Along one world axis: the part of the motion along it, scaled so a drag along the
        // axis's image direction moves it as far as the pointer.
        Vec3 unit(0, 0, 0);
        (axis == 0 ? unit.x : axis == 1 ? unit.y : unit.z) = 1;
        const Vec3 seen = camera.right * dot(unit, camera.right) + camera.up * dot(unit, camera.up);
        const double s2 = dot(seen, seen);
        move = s2 > 1e-12 ? unit * (dot(move, seen) / s2) : Vec3(0, 0, 0);
    }
    return move;
}

Shape& own_shape(Scene& scene, int primitive) {
    Primitive& prim = scene.primitives[size_t(primitive)];
    int users = 0;
    for (const Primitive& p : scene.primitives) users += p.shape == prim.shape;
    for (const Light& l : scene.lights) users += l.shape == prim.shape && prim.type != PrimitiveType::emissive;
    if (users > 1) {
        Shape copy = scene.shapes[size_t(prim.shape)];
        copy.id = unused_id(scene.shapes, copy.id);
        scene.shapes.push_back(copy);
        prim.shape = int(scene.shapes.size()) - 1;
    }
    return scene.shapes[size_t(prim.shape)];
}

int duplicate_primitive(Scene& scene, int p, const Vec3& offset) {
    Primitive copy = scene.primitives[size_t(p)];
    Shape shape = scene.shapes[size_t(copy.shape)];
    shape.id = unused_id(scene.shapes, shape.id);
    shape.centre += offset;
    scene.shapes.push_back(shape);
    copy.shape = int(scene.shapes.size()) - 1;
    copy.id = unused_id(scene.primitives, copy.id);
    if (copy.type == PrimitiveType::emissive && copy.light >= 0) {
        // Its own light, on, over the new shape.
        Light light = scene.lights[size_t(copy.light)];
        light.id = unused_id(scene.lights, light.id);
        light.shape = copy.shape;
        scene.lights.push_back(light);
        copy.light = int(scene.lights.size()) - 1;
        set_light_on(scene, copy.light, true);
    }
    scene.primitives.push_back(copy);
    return int(scene.primitives.size()) - 1;
}

void delete_primitive(Scene& scene, int p) {
    const Primitive prim = scene.primitives[size_t(p)];
    scene.primitives.erase(scene.primitives.begin() + p);
    if (prim.type == PrimitiveType::emissive && prim.light >= 0) set_light_on(scene, prim.light, false);
}

int add_sphere(Scene& scene, const Vec3& centre, double radius) {
    int material = -1;
    for (size_t i = 0; i < scene.materials.size() && material < 0; ++i)
        if (scene.materials[i].type == MaterialType::diffuse) material = int(i);
    if (material < 0) {
        Material grey;
        grey.id = unused_id(scene.materials, "grey diffuse");
        scene.materials.push_back(grey);
        material = int(scene.materials.size()) - 1;
    }
    Shape shape;
    shape.id = unused_id(scene.shapes, "sphere");
    shape.centre = centre;
    shape.radius = radius;
    scene.shapes.push_back(shape);
    Primitive prim;
    prim.id = unused_id(scene.primitives, shape.id);
    prim.shape = int(scene.shapes.size()) - 1;
    prim.material = material;
    scene.primitives.push_back(prim);
    return int(scene.primitives.size()) - 1;
}

SpherePlace free_sphere_place(const Scene& scene, const Vec3& eye, const Vec3& target, double radius) {
    // The room a point has: its distance to the nearest surface of the scene's spheres (from
    // outside, or from inside one that holds the eye too) and to the lights' points; 0 inside
    // a sphere that does not hold the eye.
    auto room = [&](const Vec3& c) {
        double free = std::numeric_limits<double>::infinity();
        for (const Primitive& prim : scene.primitives) {
            const Shape& s = scene.shapes[size_t(prim.shape)];
            const double d = length(c - s.centre);
            if (d >= s.radius) free = std::min(free, d - s.radius);
            else if (length(eye - s.centre) < s.radius) free = std::min(free, s.radius - d);
            else return 0.0;
        }
        for (int l : scene.active_lights) {
            // A light on a shape is a primitive's sphere, counted above.
            const LightAnchor anchor = light_anchor(scene.lights[size_t(l)]);
            if (anchor.kind == LightAnchor::Kind::point) free = std::min(free, length(c - anchor.point));
        }
        return free;
    };
    // From the target back towards the eye, the first point with room for the sphere, else
    // the one with the most room (at least a quarter of the radius).
    constexpr int kSteps = 64;
    SpherePlace best{target, 0};
    for (int k = 0; k < kSteps; ++k) {
        const Vec3 c = target + (eye - target) * (double(k) / kSteps);
        const double fit = 0.9 * room(c);
        if (fit >= radius) return {c, radius};
        if (fit > best.radius) best = {c, fit};
    }
    if (best.radius >= 0.25 * radius) return best;
    return {target, radius};
}

void new_material_for(Scene& scene, int p) {
    Primitive& prim = scene.primitives[size_t(p)];
    Material copy = prim.material >= 0 ? scene.materials[size_t(prim.material)] : Material{};
    copy.id = unused_id(scene.materials, prim.material >= 0 ? copy.id : std::string("material"));
    scene.materials.push_back(copy);
    prim.material = int(scene.materials.size()) - 1;
}

void set_emissive(Scene& scene, int p, bool emissive, const Color& power) {
    Primitive& prim = scene.primitives[size_t(p)];
    if (emissive == (prim.type == PrimitiveType::emissive)) return;
    if (!emissive) {
        if (prim.light >= 0) set_light_on(scene, prim.light, false);
        prim.type = PrimitiveType::geometric;
        prim.light = -1;
        return;
    }
    own_shape(scene, p);
    Light light;
    light.id = unused_id(scene.lights, prim.id + " light");
    light.type = kShapeLightType;
    light.power = power;
    light.shape = prim.shape;
    scene.lights.push_back(light);
    prim.type = PrimitiveType::emissive;
    prim.light = int(scene.lights.size()) - 1;
    set_light_on(scene, prim.light, true);
}

std::string focus_message(const Camera& camera) {
    char distance[64];
    std::snprintf(distance, sizeof distance, "%.4g", camera.focal_distance);
    std::string message = std::string("focused at distance ") + distance;
    if (!(camera.alpha > 0))
        message += "; the aperture is 0, so every distance is sharp: open it (Lens panel, aperture) to see the focus";
    return message;
}

void copy_view(const Camera& from, Camera& to) {
    to.position = from.position;
    to.target = from.target;
    to.fov = from.fov;
    to.aspect = from.aspect;
}

std::string bookmark_id(int n) { return "bookmark " + std::to_string(n); }

int find_bookmark(const Scene& scene, int n) {
    const std::string id = bookmark_id(n);
    for (size_t i = 0; i < scene.cameras.size(); ++i)
        if (scene.cameras[i].id == id) return int(i);
    return -1;
}

void store_bookmark(Scene& scene, int n) {
    Camera mark = scene.cameras[size_t(scene.camera)];
    mark.id = bookmark_id(n);
    const int at = find_bookmark(scene, n);
    // The active camera itself may be a bookmark: then it stays as it is.
    if (at == scene.camera) return;
    if (at >= 0) scene.cameras[size_t(at)] = mark;
    else scene.cameras.push_back(mark);
}

bool recall_bookmark(Scene& scene, int n) {
    const int at = find_bookmark(scene, n);
    if (at < 0) return false;
    copy_view(scene.cameras[size_t(at)], scene.cameras[size_t(scene.camera)]);
    return true;
}

Color join_power(const ColourStrength& cs) {
    auto decimal = [](double v) {
        char text[40];
        std::snprintf(text, sizeof text, "%.15g", v);
        return std::strtod(text, nullptr);
    };
    const Color p = cs.colour * cs.strength;
    return Color(decimal(p.x), decimal(p.y), decimal(p.z));
}

ColourStrength split_power(const Color& power) {
    const double strength = std::max({power.x, power.y, power.z});
    if (!(strength > 0)) return {Color(1), 0};
    return {power / strength, strength};
}

}  // namespace kr::viewer
