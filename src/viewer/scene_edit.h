// Edits of the scene's objects that the panels and the mouse make, on the authored scene,
// GL-free and unit-tested: lights on and off, picking a primitive under the pointer, and the
// selected primitive's edits (move, radius, material, emissive, duplicate, delete, add).
// A primitive is named by its index in Scene::primitives (the scene block's list).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "render/camera.h"
#include "render/render_scene.h"
#include "scene/scene.h"

namespace kr::viewer {

// Turns light `index` of the file on (into the scene block's lights) or off.
void set_light_on(Scene& scene, int index, bool on);

// The primitive whose sphere the pinhole ray through image point (fx, fy) in [0,1)^2 hits
// first, if any.
std::optional<int> pick_primitive(const Scene& scene, const CameraModel& camera, double fx, double fy);

// Where a sphere shows on the image: its centre's image point (fx, fy) and its radius as a
// fraction of the image height. None when its centre is behind the camera.
struct ImageCircle {
    double fx = 0, fy = 0, radius = 0;
};
std::optional<ImageCircle> project_sphere(const CameraModel& camera, const Vec3& centre, double radius);
// The image points (fx, fy) of `n` points around the sphere's silhouette as the camera sees
// it (an ellipse off the axis): the selection's outline. Empty when any is behind the camera.
std::vector<std::pair<double, double>> sphere_outline(const CameraModel& camera, const Vec3& centre, double radius,
                                                      int n);

// Whether the outline lies wholly on the image ([0,1]^2): where it does not (a wall, a
// sphere around the camera or cut by the image's edge), the selection is shown by its tint.
bool outline_on_image(const std::vector<std::pair<double, double>>& outline);
// The cells of a cols x rows grid over the image (row-major) whose centre's pinhole ray
// first meets the sphere (centre, radius): where the selection is seen, for its tint.
std::vector<unsigned char> sphere_coverage(const RenderScene& scene, const Vec3& centre, double radius, int cols,
                                           int rows);

// A drag of (dx, dy) image pixels moving a point at `centre` in the view plane (right, up),
// the point following the pointer at its depth; `axis` 0, 1, 2 keeps only the motion along
// world x, y or z (-1: no lock).
Vec3 drag_offset(const CameraModel& camera, const Vec3& centre, double dx_pixels, double dy_pixels, int image_height,
                 int axis);

// An id not used by any of `items` (`base`, else "base 2", "base 3", ...).
template <typename T>
std::string unused_id(const std::vector<T>& items, const std::string& base) {
    auto used = [&](const std::string& id) {
        for (const T& t : items)
            if (t.id == id) return true;
        return false;
    };
    if (!used(base)) return base;
    for (int n = 2;; ++n)
        if (!used(base + " " + std::to_string(n))) return base + " " + std::to_string(n);
}

// The selected primitive's sphere, moved to `centre` (its own shape: one shared with another
// primitive is copied first, so only the selection moves).
Shape& own_shape(Scene& scene, int primitive);
// A copy of primitive `p` (its own shape, beside the original by `offset`); returns its index.
int duplicate_primitive(Scene& scene, int p, const Vec3& offset);
// Removes primitive `p` from the scene block (an emissive one's light goes out of it too;
// the shape, material and light stay in the file's lists).
void delete_primitive(Scene& scene, int p);
// A new diffuse sphere at `centre` of `radius` (a new grey material when the file has no
// diffuse one); returns its index.
int add_sphere(Scene& scene, const Vec3& centre, double radius);
// Primitive `p` with a new material: a copy of its current one under a new id.
void new_material_for(Scene& scene, int p);
// Makes primitive `p` emissive with a new area light of `power` (on), or geometric again
// (its light goes out of the scene block).
void set_emissive(Scene& scene, int p, bool emissive, const Color& power = Color(5));

// The view of a camera (position, target, fov, aspect), copied onto another; its lens stays.
void copy_view(const Camera& from, Camera& to);

// Camera bookmarks 1..9: cameras of the file's list with the id "bookmark N", outside the
// scene block (the format keeps unreferenced cameras, and they render nothing).
std::string bookmark_id(int n);
// Index of bookmark `n` in Scene::cameras, or -1.
int find_bookmark(const Scene& scene, int n);
// Stores the active camera (its view and lens) as bookmark `n`, replacing an older one.
void store_bookmark(Scene& scene, int n);
// Puts bookmark `n`'s view on the active camera (its lens stays); false when there is none.
bool recall_bookmark(Scene& scene, int n);

// A light's power (the file's value: a point light's intensity, an area light's radiance)
// shown as a colour whose largest component is 1 times a strength: colour x strength = power.
struct ColourStrength {
    Color colour{1};
    double strength = 0;
};
ColourStrength split_power(const Color& power);
inline Color join_power(const ColourStrength& cs) { return cs.colour * cs.strength; }

}  // namespace kr::viewer
