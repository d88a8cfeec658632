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

// Why light `index` of the file, switched on, adds nothing the camera can see; empty when it
// may. A point light of power 0, or one inside a rendered sphere that does not hold the
// camera (shadow rays do not cross a sphere, so it lights only that sphere's inside); an area
// light of power 0, carried by no rendered primitive, or whose sphere lies wholly inside such
// a sphere.
std::string light_unseen_reason(const Scene& scene, int index);

// A primitive as the panels name it: its id, then its shape's where that differs
// ("sphere 01", "ball (shape sphere 3)"), and "emissive" where it is.
std::string primitive_label(const Scene& scene, int p);

// A light as the panels name it: its id, with its type where the id does not say it
// ("area light", "lamp (area light)").
std::string light_label(const Light& light);

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
// Where a new sphere of about `radius` goes on the line of sight from `eye` to `target`: the
// point nearest the target where it overlaps no sphere of the scene block (one holding the
// eye, a room's shell, counts from its inside) and holds no light, its radius shrunk to fit
// there when it must (to no less than a quarter); the target as asked when no point of the
// line has room.
struct SpherePlace {
    Vec3 centre;
    double radius = 1;
};
SpherePlace free_sphere_place(const Scene& scene, const Vec3& eye, const Vec3& target, double radius);
// Primitive `p` with a new material: a copy of its current one under a new id.
void new_material_for(Scene& scene, int p);
// Makes primitive `p` emissive with a new area light of `power` (on), or geometric again
// (its light goes out of the scene block).
void set_emissive(Scene& scene, int p, bool emissive, const Color& power = Color(5));

// What a click-to-focus says: the focal distance set, and, where the aperture is closed
// (alpha 0: every distance is sharp, the image unchanged), how to see the focus.
std::string focus_message(const Camera& camera);

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
// Each component to 15 significant digits: 0.9 x 30 is 27, not 27.000000000000004.
Color join_power(const ColourStrength& cs);

}  // namespace kr::viewer
