// The prepared render scene: only what the authored scene's `scene` block references,
// flattened into arrays the integrators read, plus ray casting against it.
// Rebuilt from the authored scene (scene/scene.h) after every edit.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "core/math.h"
#include "render/accel.h"
#include "render/camera.h"
#include "scene/scene.h"

namespace kr {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A ray segment <O, D, tmin, tmax>. D is unit length. Only roots with t > 0 count.
// A ray that leaves a sphere's surface names it in `from_sphere`: spheres are convex, so a
// ray heading out of it can never hit it again and one heading into it can only hit its far
// side. Skipping that sphere (or its near root) replaces epsilon offsets, which fail across
// the scales of a radius-1e-4 ball and a radius-1e6 wall. `to_sphere` is skipped too: shadow
// rays end on it.
struct Ray {
    Vec3 o, d;
    double tmin = 0, tmax = kInfinity;
    int from_sphere = -1;
    bool into_from_sphere = false;
    int to_sphere = -1;
};

struct Hit {
    double t = kInfinity;
    int sphere = -1;
    Vec3 p;  // on the sphere
    Vec3 n;  // outward unit normal
};

struct SphereGeom {
    Vec3 centre;
    double radius = 1;
    bool operator==(const SphereGeom&) const = default;
};

// A light of the scene block as the integrators read it. Each type's physics is in
// lanes/vertex.inc, section "Lights" (light_kind says what the type is; light_direct samples it).
struct RenderLight {
    LightType type = LightType::point;
    Color power;     // point: radiant intensity (W/sr per channel); area: emitted radiance
    Vec3 position;   // point: where it is
    int sphere = -1; // area: the sphere that emits, from both sides of its surface
    double select_prob = 0;  // the chance next-event estimation takes it (by power)
    bool operator==(const RenderLight&) const = default;
};

struct RenderScene {
    std::vector<SphereGeom> spheres;
    std::vector<int> sphere_material;  // per sphere: index into materials
    std::vector<int> sphere_light;     // per sphere: index into lights of the light it carries, or -1
    std::vector<Material> materials;   // only those the primitives use
    // The active lights: first those off the spheres (no ray finds them by chance, so naive
    // path tracing samples only these) in the order /scene/lights lists them, then those on
    // the spheres (light_kind's on_sphere) in the spheres' order.
    std::vector<RenderLight> lights;
    size_t lights_off_spheres = 0;  // how many lights come first, off the spheres
    CameraModel camera;
    RendererSettings renderer;  // the file's renderer block

    SphereBvh bvh;  // over `spheres`; built by prepare_scene (call build_accel after edits)
    AccelBackend accel_backend = AccelBackend::automatic;  // which BVH build_accel makes
    bool linear_scan = false;  // test every sphere instead of the BVH (the plain path, for checks)
    // float_resolves_gaps (precision.h) of the spheres and lights, as prepare_scene and
    // build_accel found it: whether single-precision lanes may cast its rays (false, and not
    // examined, where its BVH gives the lanes nothing to cast them with).
    bool float_gaps_resolved = false;

    // Closest hit within [tmin, tmax]. Fills `hit` and returns true if there is one.
    bool intersects(const Ray& ray, Hit& hit) const;
    // Any hit within [tmin, tmax].
    bool is_occluded(const Ray& ray) const;
    // The same two by testing every sphere in turn: the plain path the BVH is checked against.
    bool intersects_linear(const Ray& ray, Hit& hit) const;
    // The hit of `ray` on sphere `sphere` as intersects gives it where that sphere is the
    // closest; false where the ray does not hit it (accepted_root).
    bool hit_on(const Ray& ray, int sphere, Hit& hit) const;
    bool is_occluded_linear(const Ray& ray) const;
    // Builds the BVH over `spheres` (after edits to them or to the lights) and checks the gaps
    // between them again.
    void build_accel();
    size_t light_count() const { return lights.size(); }
};

// Whether `a` and `b` render the same image (the same samples): their spheres, each sphere's
// material parameters (not its id: a copy under a new name renders the same) and light, the
// lights, the camera (a focal distance only where the lens is open) and the renderer block.
// The viewer restarts its render only when an edit changes this. A member that changes the
// samples joins it.
bool renders_same(const RenderScene& a, const RenderScene& b);
// Whether each surface point of `a` and `b` sends the same radiance every way: renders_same
// without the camera and what only changes the samples (the spp, the BVH kind).
bool same_world(const RenderScene& a, const RenderScene& b);

// A shadow segment towards a point light ends on that point, and the point may lie on a
// surface (a light placed on a floor or wall). Rounding then puts the surface's crossing a
// hair before or after the end, so shadows would speckle at random. is_occluded therefore
// ends a finite segment short of tmax by this fraction of the magnitudes the root is computed
// from (|o - centre| in the 1-norm, plus tmax): a crossing that close to the end is the end
// point itself. Scale-free, like the rest of the ray rules; closest-hit queries are exact.
inline constexpr double kSegmentEndTolerance = 64 * std::numeric_limits<double>::epsilon();
double segment_end_tolerance(const Vec3& origin_minus_centre, double tmax);

// Ray-sphere roots of |o + t d - c|^2 = r^2 for unit d, in a cancellation-free form
// (Haines et al., Ray Tracing Gems ch. 7). Returns false when the line misses.
bool sphere_roots(const SphereGeom& s, const Vec3& o, const Vec3& d, double& t_near, double& t_far);

// The distance at which `ray` hits sphere `s` (index `index` of the scene), or +inf: the
// from/to sphere rules of Ray, only roots ahead of the origin (t > 0), within [tmin, tmax];
// `shadow` leaves out a crossing at a segment's very end (kSegmentEndTolerance). The plain
// path's test, and Embree's intersection callback.
double accepted_root(const SphereGeom& s, int index, const Ray& ray, bool shadow);

// Builds the render scene from what `scene.scene` references. Identical repeated primitives
// (same shape) are merged, with a warning if their materials differ. Throws SceneError for
// problems only visible at this stage (e.g. an active area light no primitive carries).
// `previous`, the render scene before an edit: where the edit moved no sphere (camera, lens,
// material, light power, renderer settings), its BVH is kept rather than built again.
RenderScene prepare_scene(const Scene& scene, std::vector<std::string>* warnings = nullptr,
                          const RenderScene* previous = nullptr);

}  // namespace kr
