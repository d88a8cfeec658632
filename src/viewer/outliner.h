// The outliner's rows and the commands over the selection (GL-free): every object, light
// and camera of a scene as the Outliner panel lists them; "frame selected" and the axis views
// (camera edits); the selection's own material, which its edits change.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace kr::viewer {

enum class OutlinerKind { object, light, camera };

struct OutlinerRow {
    OutlinerKind kind = OutlinerKind::object;
    int index = 0;       // into Scene::primitives, lights or cameras
    std::string label;   // "sphere 01", "area light", "pinhole"
    std::string detail;  // "diffuse 'white'", "on", "active"
};

// Objects (the primitives, in the scene block's order), then every light of the file (on or
// off), then every camera (bookmarks included).
std::vector<OutlinerRow> outliner_rows(const Scene& scene);
// One of them (the panel makes only the rows it shows: a scene may hold many spheres).
OutlinerRow outliner_row(const Scene& scene, OutlinerKind kind, int index);
// How many rows of each kind: primitives, lights, cameras.
int outliner_count(const Scene& scene, OutlinerKind kind);

// Whether a row matches the outliner's filter: `filter`'s text (case-insensitive, spaces at
// its ends ignored) in its label or its detail ("glass", "off", "emissive"); an empty filter
// matches every row.
bool outliner_row_matches(const OutlinerRow& row, std::string_view filter);

// What the window has selected: a primitive (a click on the image, or its row), or a light
// with no primitive of its own (a point light, or an area light no primitive carries).
struct Selection {
    std::optional<int> primitive;
    std::optional<int> light;
};

// The selection a row selects: an object's primitive; a light's emissive primitive where one
// carries it, else the light; a camera selects nothing (its row makes it the active one).
Selection row_selection(const Scene& scene, const OutlinerRow& row);

// The ball the selection occupies: a sphere's centre and radius; a point light's position
// and radius 0. None for an invalid selection.
struct Ball {
    Vec3 centre;
    double radius = 0;
};
std::optional<Ball> selection_ball(const Scene& scene, const Selection& selection);

// The share of the narrower half field of view that a framed ball fills.
inline constexpr double kFrameFill = 0.7;

// "Frame selected": the camera looking at `ball` from the direction it looks now (its target
// the ball's centre), at the distance where the ball's angular radius is kFrameFill of the
// narrower half field of view. A ball of radius 0 keeps the camera's distance. A lens-based
// camera focuses on the ball's centre (the plane in focus follows what the view is framed on).
Camera framed(const Camera& camera, const Ball& ball);

// Blender's numpad views: looking along a world axis at the camera's target from its distance.
// front looks along +z (the scenes' default view), right along -x, top down along -y; back,
// left and bottom the other way.
enum class AxisView { front, back, right, left, top, bottom };
Camera axis_view(const Camera& camera, AxisView view);
const char* axis_view_name(AxisView view);

// How many primitives use material `m`.
int material_users(const Scene& scene, int m);
// The material of primitive `p` that only it uses: its own when no other primitive shares it,
// else a copy made for it (new_material_for). Returns the material's index.
int own_material(Scene& scene, int p);

// The Selection panel's one-click colours: a name and a diffuse reflectance.
struct PaletteColour {
    const char* name;
    Color rho;
};
inline constexpr PaletteColour kPalette[] = {
    {"white", Color(0.8, 0.8, 0.8)},  {"grey", Color(0.4, 0.4, 0.4)},   {"red", Color(0.8, 0.1, 0.1)},
    {"orange", Color(0.9, 0.45, 0.1)}, {"yellow", Color(0.85, 0.8, 0.15)}, {"green", Color(0.15, 0.7, 0.2)},
    {"blue", Color(0.15, 0.3, 0.85)},  {"purple", Color(0.55, 0.2, 0.75)},
};

// Recolours primitive `p` alone: its own material (own_material) gets `colour` as its first
// colour parameter (rho for the reflectors, rhoT for the dielectrics). False when the
// primitive's material has no colour parameter.
bool recolour_primitive(Scene& scene, int p, const Color& colour);

}  // namespace kr::viewer
